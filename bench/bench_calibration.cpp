// Clock calibration, for expressing kernel rates as a fraction of the core's
// peak on machines without hardware counters: a chain of dependent integer
// additions retires exactly one per cycle (1-cycle latency on every x86 core
// since the P6), so additions per second = cycles per second.
#include <benchmark/benchmark.h>

#include <cstdint>

namespace {

void calibration_cycles(benchmark::State& state) {
    constexpr std::int64_t kAdds = 1 << 20;
    std::uint64_t x = 1;
    for (auto _ : state) {
        for (std::int64_t i = 0; i < kAdds; i += 8) {
            // Eight dependent adds per iteration keep the loop overhead off
            // the critical path; asm keeps the compiler from folding them.
            asm volatile(
                "add %0, %0\n\tadd %0, %0\n\tadd %0, %0\n\tadd %0, %0\n\t"
                "add %0, %0\n\tadd %0, %0\n\tadd %0, %0\n\tadd %0, %0"
                : "+r"(x));
        }
    }
    benchmark::DoNotOptimize(x);
    state.counters["cycles_per_second"] =
        benchmark::Counter(double(state.iterations()) * double(kAdds), benchmark::Counter::kIsRate);
}
BENCHMARK(calibration_cycles)->Name("calibration/cycles");

}  // namespace
