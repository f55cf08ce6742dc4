// What one instruction takes from the zmm FMA pipes, measured without
// hardware counters. A loop of 8 independent zmm FMAs is FMA-bound; the same
// loop with N independent copies of the instruction under test added runs
// longer only by what those copies need of the FMA pipes (or, past two
// 512-bit instructions a cycle, of the issue width). Both loops are timed
// alternately inside each benchmark iteration, so the reported ratio comes
// from one run on a shared machine:
//   fma_cycles = (time with the N copies / time without - 1) x 8 / N,
// in units of one zmm FMA. docs/kernels.md, "Speed-ups over width 1", uses these to
// bound the width-16 triangle kernel. AVX-512 (F, DQ, VL) builds only.
#include <benchmark/benchmark.h>

#if defined(__x86_64__) && defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__)

#include <chrono>

namespace {

// Inputs stay in zmm20/zmm21 (never written); the FMAs accumulate into
// zmm0-7, zeroed first (+1 per step: no overflow, no subnormals);
// instructions under test write zmm8-15 or k1-k4 so that no copy waits for
// another.
#define RP_FMA8                                                                                          \
    "vfmadd231ps %%zmm20, %%zmm21, %%zmm0\n\tvfmadd231ps %%zmm20, %%zmm21, %%zmm1\n\t"                  \
    "vfmadd231ps %%zmm20, %%zmm21, %%zmm2\n\tvfmadd231ps %%zmm20, %%zmm21, %%zmm3\n\t"                  \
    "vfmadd231ps %%zmm20, %%zmm21, %%zmm4\n\tvfmadd231ps %%zmm20, %%zmm21, %%zmm5\n\t"                  \
    "vfmadd231ps %%zmm20, %%zmm21, %%zmm6\n\tvfmadd231ps %%zmm20, %%zmm21, %%zmm7\n\t"

#define RP_ZERO_ACCUMULATORS                                                                             \
    "vpxord %%zmm0, %%zmm0, %%zmm0\n\tvpxord %%zmm1, %%zmm1, %%zmm1\n\tvpxord %%zmm2, %%zmm2, %%zmm2\n\t"  \
    "vpxord %%zmm3, %%zmm3, %%zmm3\n\tvpxord %%zmm4, %%zmm4, %%zmm4\n\tvpxord %%zmm5, %%zmm5, %%zmm5\n\t"  \
    "vpxord %%zmm6, %%zmm6, %%zmm6\n\tvpxord %%zmm7, %%zmm7, %%zmm7\n\tvpxord %%zmm8, %%zmm8, %%zmm8\n\t"  \
    "vpxord %%zmm9, %%zmm9, %%zmm9\n\tvpxord %%zmm10, %%zmm10, %%zmm10\n\tvpxord %%zmm11, %%zmm11, %%zmm11\n\t"

#define RP_LOOP(BODY)                                                                                    \
    asm volatile("vbroadcastss %1, %%zmm20\n\tvbroadcastss %1, %%zmm21\n\t"                             \
                 "kxnorw %%k1, %%k1, %%k1\n\tkxnorw %%k2, %%k2, %%k2\n\t" RP_ZERO_ACCUMULATORS             \
                 "mov %0, %%rcx\n\t"                                                                    \
                 "1:\n\t" BODY "dec %%rcx\n\tjnz 1b"                                                      \
                 :                                                                                      \
                 : "r"(kSteps), "m"(kOne)                                                               \
                 : "rcx", "k1", "k2", "k3", "k4", "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6",  \
                   "xmm7", "xmm8", "xmm9", "xmm10", "xmm11", "xmm12", "xmm13", "xmm14", "xmm15", "xmm20",   \
                   "xmm21", "cc")

constexpr long kSteps = 4096;
const float kOne = 1.0f;

using Clock = std::chrono::steady_clock;

template <class Loop>
double seconds(Loop loop) {
    const auto t0 = Clock::now();
    loop();
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Times the base loop and the loop with `added` copies alternately.
template <class Base, class Mixed>
void pipe_cost(benchmark::State& state, int added, Base base, Mixed mixed) {
    double t_base = 0, t_mixed = 0;
    for (auto _ : state) {
        t_base += seconds(base);
        t_mixed += seconds(mixed);
    }
    state.counters["fma_cycles"] = (t_mixed / t_base - 1.0) * 8.0 / double(added);
}

void base_loop() { RP_LOOP(RP_FMA8); }

#define RP_CASE(NAME, ADDED, BODY)                                                                       \
    void NAME(benchmark::State& state) {                                                                 \
        pipe_cost(state, ADDED, base_loop, [] { RP_LOOP(RP_FMA8 BODY); });                               \
    }

// Four copies keep the loop under two 512-bit instructions a cycle (12 in 8
// cycles), so an instruction that issues beside the FMAs costs ~0.
RP_CASE(fma, 4, "vfmadd231ps %%zmm20, %%zmm21, %%zmm8\n\tvfmadd231ps %%zmm20, %%zmm21, %%zmm9\n\t"
                "vfmadd231ps %%zmm20, %%zmm21, %%zmm10\n\tvfmadd231ps %%zmm20, %%zmm21, %%zmm11\n\t")
RP_CASE(mul, 4, "vmulps %%zmm20, %%zmm21, %%zmm8\n\tvmulps %%zmm20, %%zmm21, %%zmm9\n\t"
                "vmulps %%zmm20, %%zmm21, %%zmm10\n\tvmulps %%zmm20, %%zmm21, %%zmm11\n\t")
RP_CASE(cmp_to_mask, 4, "vcmpps $1, %%zmm20, %%zmm21, %%k1\n\tvcmpps $2, %%zmm20, %%zmm21, %%k2\n\t"
                        "vcmpps $1, %%zmm21, %%zmm20, %%k3\n\tvcmpps $2, %%zmm21, %%zmm20, %%k4\n\t")
RP_CASE(int_cmp_to_mask, 4, "vpcmpud $1, %%zmm20, %%zmm21, %%k1\n\tvpcmpud $2, %%zmm20, %%zmm21, %%k2\n\t"
                            "vpcmpud $1, %%zmm21, %%zmm20, %%k3\n\tvpcmpud $2, %%zmm21, %%zmm20, %%k4\n\t")
RP_CASE(sign_to_mask, 4, "vpmovd2m %%zmm20, %%k1\n\tvpmovd2m %%zmm21, %%k2\n\t"
                         "vpmovd2m %%zmm20, %%k3\n\tvpmovd2m %%zmm21, %%k4\n\t")
RP_CASE(div, 1, "vdivps %%zmm20, %%zmm21, %%zmm8\n\t")
RP_CASE(add, 4, "vaddps %%zmm20, %%zmm21, %%zmm8\n\tvaddps %%zmm20, %%zmm21, %%zmm9\n\t"
                "vaddps %%zmm20, %%zmm21, %%zmm10\n\tvaddps %%zmm20, %%zmm21, %%zmm11\n\t")
RP_CASE(min, 4, "vminps %%zmm20, %%zmm21, %%zmm8\n\tvminps %%zmm20, %%zmm21, %%zmm9\n\t"
                "vminps %%zmm20, %%zmm21, %%zmm10\n\tvminps %%zmm20, %%zmm21, %%zmm11\n\t")
RP_CASE(logic, 4, "vpxord %%zmm20, %%zmm21, %%zmm8\n\tvpxord %%zmm20, %%zmm21, %%zmm9\n\t"
                  "vpxord %%zmm20, %%zmm21, %%zmm10\n\tvpxord %%zmm20, %%zmm21, %%zmm11\n\t")
RP_CASE(blend, 4, "vblendmps %%zmm20, %%zmm21, %%zmm8%{%%k1%}\n\tvblendmps %%zmm20, %%zmm21, %%zmm9%{%%k1%}\n\t"
                  "vblendmps %%zmm20, %%zmm21, %%zmm10%{%%k1%}\n\tvblendmps %%zmm20, %%zmm21, %%zmm11%{%%k1%}\n\t")
RP_CASE(mask_and, 4, "kandw %%k1, %%k2, %%k3\n\tkandw %%k2, %%k1, %%k4\n\t"
                     "kandw %%k1, %%k2, %%k3\n\tkandw %%k2, %%k1, %%k4\n\t")
RP_CASE(ymm_cmp_to_vector, 4, "vcmpps $1, %%ymm10, %%ymm11, %%ymm12\n\tvcmpps $2, %%ymm10, %%ymm11, %%ymm13\n\t"
                              "vcmpps $1, %%ymm11, %%ymm10, %%ymm14\n\tvcmpps $2, %%ymm11, %%ymm10, %%ymm15\n\t")

BENCHMARK(fma)->Name("pipes/zmm_fma");
BENCHMARK(mul)->Name("pipes/zmm_mul");
BENCHMARK(cmp_to_mask)->Name("pipes/zmm_cmpps_to_k");
BENCHMARK(int_cmp_to_mask)->Name("pipes/zmm_pcmpud_to_k");
BENCHMARK(sign_to_mask)->Name("pipes/zmm_pmovd2m_to_k");
BENCHMARK(div)->Name("pipes/zmm_divps");
BENCHMARK(add)->Name("pipes/zmm_addps");
BENCHMARK(min)->Name("pipes/zmm_minps");
BENCHMARK(logic)->Name("pipes/zmm_pxord");
BENCHMARK(blend)->Name("pipes/zmm_blendmps");
BENCHMARK(mask_and)->Name("pipes/kandw");
BENCHMARK(ymm_cmp_to_vector)->Name("pipes/ymm_cmpps_to_vector");

}  // namespace

#endif
