// Slab-test microbenchmarks: aabb/VARIANT/K (K rays against one box) and
// aabb_1xM/VARIANT/M (one ray against a block of M boxes in SoA).
#include <bit>

#include "bench/kernel_bench.h"
#include "kernels/aabb.h"

namespace raypack::bench {
namespace {

// 512 rays x 44 bytes stay in L1, so the loop measures the kernel, not memory.
constexpr std::size_t kRays = 512;

// Box around the origin that about half of make_rays() hit.
const Vec3f kLo{-0.15f, -0.2f, -0.3f}, kHi{0.2f, 0.15f, 0.3f};

template <SlabMethod M, class F>
RAYPACK_INLINE std::uint32_t box_hits(const SlabRay<F>& r, const Vec3<F>& lo, const Vec3<F>& hi) {
    F entry;
    return mask_bits(intersect_box<M, F>(mask_of<F>(true), r, lo, hi, entry));
}

/// The slab view of rays i .. i+lanes-1 (or of ray i broadcast); org * rdir is
/// part of the per-ray precomputation, like rdir.
template <class F>
RAYPACK_INLINE SlabRay<F> slab_rays(const RayLanes<F>& r) {
    return make_slab_ray(r.org, r.rdir, r.tnear, r.tfar);
}

template <SlabMethod M, int K>
void aabb_packet(benchmark::State& state) {
    using F = vfloat<K>;
    const RaySoA rays = make_rays(kRays);
    const Vec3<F> lo{F(kLo.x), F(kLo.y), F(kLo.z)}, hi{F(kHi.x), F(kHi.y), F(kHi.z)};
    std::vector<SlabRay<F>> packets;
    for (std::size_t i = 0; i < rays.n; i += K) packets.push_back(slab_rays(load_rays<F>(rays, i)));
    // Validate every lane against the width-1 path before timing.
    std::size_t hits = 0;
    bool same = true;
    for (std::size_t i = 0; i < rays.n; i += K) {
        const std::uint32_t bits = box_hits<M, F>(packets[i / K], lo, hi);
        for (int l = 0; l < K; ++l) {
            const bool scalar = box_hits<M, float>(slab_rays(load_rays<float>(rays, i + std::size_t(l))), kLo, kHi) != 0;
            same &= scalar == (((bits >> l) & 1u) != 0);
            hits += scalar;
        }
    }
    if (!validated(state, same && hits > 0 && hits < rays.n, "packet lanes differ from the scalar slab test")) return;
    for (auto _ : state) {
        std::uint32_t count = 0;
        for (const SlabRay<F>& packet : packets) count += std::popcount(box_hits<M, F>(packet, lo, hi));
        benchmark::DoNotOptimize(count);
    }
    set_tests_per_second(state, double(rays.n));
}

/// M boxes around the origin, scaled and shifted so that they differ.
struct BoxBlock {
    std::vector<float> lx, ly, lz, hx, hy, hz;
};

BoxBlock make_boxes(int m) {
    BoxBlock b;
    for (int j = 0; j < m; ++j) {
        const float s = 0.5f + 0.1f * float(j % 5), dx = 0.05f * float(j % 3) - 0.05f;
        b.lx.push_back(kLo.x * s + dx); b.ly.push_back(kLo.y * s); b.lz.push_back(kLo.z * s);
        b.hx.push_back(kHi.x * s + dx); b.hy.push_back(kHi.y * s); b.hz.push_back(kHi.z * s);
    }
    return b;
}

template <SlabMethod M, int Width>
void aabb_1xM(benchmark::State& state) {
    using F = vfloat<Width>;
    const RaySoA rays = make_rays(kRays);
    const BoxBlock b = make_boxes(Width);
    const Vec3<F> lo{load_lanes<F>(b.lx.data()), load_lanes<F>(b.ly.data()), load_lanes<F>(b.lz.data())};
    const Vec3<F> hi{load_lanes<F>(b.hx.data()), load_lanes<F>(b.hy.data()), load_lanes<F>(b.hz.data())};
    std::vector<SlabRay<F>> broadcast;
    for (std::size_t i = 0; i < rays.n; ++i) broadcast.push_back(slab_rays(broadcast_ray<F>(rays, i)));
    bool same = true;
    std::size_t hits = 0;
    for (std::size_t i = 0; i < rays.n; ++i) {
        const std::uint32_t bits = box_hits<M, F>(broadcast[i], lo, hi);
        const SlabRay<float> r = slab_rays(load_rays<float>(rays, i));
        for (int j = 0; j < Width; ++j) {
            const bool scalar = box_hits<M, float>(r, Vec3f{b.lx[j], b.ly[j], b.lz[j]}, Vec3f{b.hx[j], b.hy[j], b.hz[j]}) != 0;
            same &= scalar == (((bits >> j) & 1u) != 0);
            hits += scalar;
        }
    }
    if (!validated(state, same && hits > 0 && hits < rays.n * Width, "block lanes differ from the scalar slab test")) return;
    for (auto _ : state) {
        std::uint32_t count = 0;
        for (const SlabRay<F>& ray : broadcast) count += std::popcount(box_hits<M, F>(ray, lo, hi));
        benchmark::DoNotOptimize(count);
    }
    set_tests_per_second(state, double(rays.n) * Width);
}

BENCHMARK_TEMPLATE(aabb_packet, SlabMethod::Plain, 1)->Name("aabb/plain/1");
BENCHMARK_TEMPLATE(aabb_packet, SlabMethod::Plain, 4)->Name("aabb/plain/4");
BENCHMARK_TEMPLATE(aabb_packet, SlabMethod::Plain, 8)->Name("aabb/plain/8");
BENCHMARK_TEMPLATE(aabb_packet, SlabMethod::Robust, 1)->Name("aabb/robust/1");
BENCHMARK_TEMPLATE(aabb_packet, SlabMethod::Robust, 4)->Name("aabb/robust/4");
BENCHMARK_TEMPLATE(aabb_packet, SlabMethod::Robust, 8)->Name("aabb/robust/8");
BENCHMARK_TEMPLATE(aabb_1xM, SlabMethod::Plain, 1)->Name("aabb_1xM/plain/1");
BENCHMARK_TEMPLATE(aabb_1xM, SlabMethod::Plain, 4)->Name("aabb_1xM/plain/4");
BENCHMARK_TEMPLATE(aabb_1xM, SlabMethod::Plain, 8)->Name("aabb_1xM/plain/8");
BENCHMARK_TEMPLATE(aabb_1xM, SlabMethod::Robust, 1)->Name("aabb_1xM/robust/1");
BENCHMARK_TEMPLATE(aabb_1xM, SlabMethod::Robust, 4)->Name("aabb_1xM/robust/4");
BENCHMARK_TEMPLATE(aabb_1xM, SlabMethod::Robust, 8)->Name("aabb_1xM/robust/8");
#if defined(__AVX512BW__)
BENCHMARK_TEMPLATE(aabb_packet, SlabMethod::Plain, 16)->Name("aabb/plain/16");
BENCHMARK_TEMPLATE(aabb_packet, SlabMethod::Robust, 16)->Name("aabb/robust/16");
BENCHMARK_TEMPLATE(aabb_1xM, SlabMethod::Plain, 16)->Name("aabb_1xM/plain/16");
BENCHMARK_TEMPLATE(aabb_1xM, SlabMethod::Robust, 16)->Name("aabb_1xM/robust/16");
#endif

}  // namespace
}  // namespace raypack::bench
