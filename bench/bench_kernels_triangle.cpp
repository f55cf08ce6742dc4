// Ray-triangle microbenchmarks: triangle/VARIANT/K (K rays against one
// triangle) and triangle_1xM/VARIANT/M (one ray against a block of M
// triangles in SoA). Every hit's t, u, v are kept (selected into running
// values), as a closest-hit loop would, so no output is dead code.
#include <bit>

#include "bench/kernel_bench.h"
#include "kernels/triangle.h"

namespace raypack::bench {
namespace {

// 512 rays stay in L1 (the largest, the watertight rays with their
// precomputed shear and axis masks, take 22 KB at K = 8), so the loop
// measures the kernel.
constexpr std::size_t kRays = 512;

// A triangle around the origin that about a third of make_rays() hit.
const Vec3f kP0{-0.4f, -0.35f, 0.1f}, kP1{0.45f, -0.3f, -0.1f}, kP2{-0.05f, 0.45f, 0.05f};

/// What each variant needs per ray, precomputed once like rdir for the slab
/// test: origin and direction, or for the watertight test the permutation
/// and shear of Woop et al.
template <TriangleMethod M, class F>
struct PreparedRay {
    Vec3<F> org, dir;
    F tnear, tfar;
};
template <class F>
struct PreparedRay<TriangleMethod::Watertight, F> {
    WatertightRay<F> ray;
    F tnear, tfar;
};

template <TriangleMethod M, class F>
PreparedRay<M, F> prepare(const RayLanes<F>& r) {
    if constexpr (M == TriangleMethod::Watertight) return {make_watertight_ray(r.org, r.dir), r.tnear, r.tfar};
    else return {r.org, r.dir, r.tnear, r.tfar};
}

template <TriangleMethod M, class F>
RAYPACK_INLINE mask_of<F> tri_test(const PreparedRay<M, F>& r, const Vec3<F>& p0, const Vec3<F>& p1,
                                   const Vec3<F>& p2, F& t, F& u, F& v) {
    const mask_of<F> all(true);
    if constexpr (M == TriangleMethod::Moeller)
        return intersect_triangle_moeller<F>(all, r.org, r.dir, r.tnear, r.tfar, p0, p1, p2, t, u, v);
    else if constexpr (M == TriangleMethod::Watertight)
        return intersect_triangle_watertight<F>(all, r.ray, r.tnear, r.tfar, p0, p1, p2, t, u, v);
    else
        return intersect_triangle_plane<F>(all, r.org, r.dir, r.tnear, r.tfar, p0, p1, p2, t, u, v);
}

/// Running closest-hit-like state: each hit overwrites its lane of t, u, v
/// (which consumes the hit mask too). Plain locals, so that they stay in
/// registers through the loop.
template <class F>
RAYPACK_INLINE void keep(const mask_of<F>& m, const F& t, const F& u, const F& v, F& kt, F& ku, F& kv) {
    kt = select(m, t, kt);
    ku = select(m, u, ku);
    kv = select(m, v, kv);
}

/// Publishes copies: DoNotOptimize on the running values themselves would
/// give them a home in memory, stored to on every iteration.
template <class F>
RAYPACK_INLINE void publish(F kt, F ku, F kv) {
    benchmark::DoNotOptimize(kt);
    benchmark::DoNotOptimize(ku);
    benchmark::DoNotOptimize(kv);
}

bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

/// Lane l of a packet answer equals the width-1 answer: the same hit, and on
/// a hit the same t, u, v bit for bit.
template <class F>
bool lane_matches(const mask_of<F>& m, const F& t, const F& u, const F& v, int l, bool hit1, float t1, float u1,
                  float v1) {
    if (lane(m, l) != hit1) return false;
    return !hit1 || (same_bits(lane(t, l), t1) && same_bits(lane(u, l), u1) && same_bits(lane(v, l), v1));
}

template <TriangleMethod M, int K>
void triangle_packet(benchmark::State& state) {
    using F = vfloat<K>;
    const RaySoA rays = make_rays(kRays);
    const Vec3<F> p0{F(kP0.x), F(kP0.y), F(kP0.z)}, p1{F(kP1.x), F(kP1.y), F(kP1.z)},
        p2{F(kP2.x), F(kP2.y), F(kP2.z)};
    std::vector<PreparedRay<M, F>> packets;
    for (std::size_t i = 0; i < rays.n; i += K) packets.push_back(prepare<M>(load_rays<F>(rays, i)));
    // Validate every lane against the width-1 path before timing.
    std::size_t hits = 0;
    bool same = true;
    for (std::size_t i = 0; i < rays.n; i += K) {
        F t(0.0f), u(0.0f), v(0.0f);
        const mask_of<F> m = tri_test<M, F>(packets[i / K], p0, p1, p2, t, u, v);
        for (int l = 0; l < K; ++l) {
            float t1 = 0, u1 = 0, v1 = 0;
            const bool h = tri_test<M, float>(prepare<M>(load_rays<float>(rays, i + std::size_t(l))), kP0, kP1, kP2,
                                              t1, u1, v1);
            same &= lane_matches(m, t, u, v, l, h, t1, u1, v1);
            hits += h;
        }
    }
    if (!validated(state, same && hits > 0 && hits < rays.n, "packet lanes differ from the width-1 triangle test"))
        return;
    for (auto _ : state) {
        F kt = F(0.0f), ku = F(0.0f), kv = F(0.0f);
        for (const auto& r : packets) {
            F t = F(0.0f), u = F(0.0f), v = F(0.0f);
            const mask_of<F> m = tri_test<M, F>(r, p0, p1, p2, t, u, v);
            keep(m, t, u, v, kt, ku, kv);
        }
        publish(kt, ku, kv);
    }
    set_tests_per_second(state, double(rays.n));
}

/// M triangles around kP0..kP2, scaled and shifted so that they differ.
struct TriangleBlock {
    std::vector<float> c[9];  // p0.xyz, p1.xyz, p2.xyz, one float per triangle each
    Vec3f p(int j, int k) const { return {c[3 * k][j], c[3 * k + 1][j], c[3 * k + 2][j]}; }
};

TriangleBlock make_triangles(int m) {
    TriangleBlock b;
    for (int j = 0; j < m; ++j) {
        const float s = 0.6f + 0.1f * float(j % 5), dx = 0.05f * float(j % 3) - 0.05f, dz = 0.02f * float(j % 4);
        for (int k = 0; k < 3; ++k) {
            const Vec3f p = k == 0 ? kP0 : k == 1 ? kP1 : kP2;
            b.c[3 * k].push_back(p.x * s + dx);
            b.c[3 * k + 1].push_back(p.y * s);
            b.c[3 * k + 2].push_back(p.z * s + dz);
        }
    }
    return b;
}

template <TriangleMethod M, int Width>
void triangle_1xM(benchmark::State& state) {
    using F = vfloat<Width>;
    const RaySoA rays = make_rays(kRays);
    const TriangleBlock b = make_triangles(Width);
    auto lanes = [&](int k) {
        return Vec3<F>{load_lanes<F>(b.c[3 * k].data()), load_lanes<F>(b.c[3 * k + 1].data()),
                       load_lanes<F>(b.c[3 * k + 2].data())};
    };
    const Vec3<F> p0 = lanes(0), p1 = lanes(1), p2 = lanes(2);
    std::vector<PreparedRay<M, F>> broadcast;
    for (std::size_t i = 0; i < rays.n; ++i) broadcast.push_back(prepare<M>(broadcast_ray<F>(rays, i)));
    bool same = true;
    std::size_t hits = 0;
    for (std::size_t i = 0; i < rays.n; ++i) {
        F t(0.0f), u(0.0f), v(0.0f);
        const mask_of<F> m = tri_test<M, F>(broadcast[i], p0, p1, p2, t, u, v);
        const PreparedRay<M, float> r = prepare<M>(load_rays<float>(rays, i));
        for (int j = 0; j < Width; ++j) {
            float t1 = 0, u1 = 0, v1 = 0;
            const bool h = tri_test<M, float>(r, b.p(j, 0), b.p(j, 1), b.p(j, 2), t1, u1, v1);
            same &= lane_matches(m, t, u, v, j, h, t1, u1, v1);
            hits += h;
        }
    }
    if (!validated(state, same && hits > 0 && hits < rays.n * Width, "block lanes differ from the width-1 triangle test"))
        return;
    for (auto _ : state) {
        F kt = F(0.0f), ku = F(0.0f), kv = F(0.0f);
        for (const auto& r : broadcast) {
            F t = F(0.0f), u = F(0.0f), v = F(0.0f);
            const mask_of<F> m = tri_test<M, F>(r, p0, p1, p2, t, u, v);
            keep(m, t, u, v, kt, ku, kv);
        }
        publish(kt, ku, kv);
    }
    set_tests_per_second(state, double(rays.n) * Width);
}

using TM = TriangleMethod;
BENCHMARK_TEMPLATE(triangle_packet, TM::Moeller, 1)->Name("triangle/moeller/1");
BENCHMARK_TEMPLATE(triangle_packet, TM::Moeller, 4)->Name("triangle/moeller/4");
BENCHMARK_TEMPLATE(triangle_packet, TM::Moeller, 8)->Name("triangle/moeller/8");
BENCHMARK_TEMPLATE(triangle_packet, TM::Watertight, 1)->Name("triangle/watertight/1");
BENCHMARK_TEMPLATE(triangle_packet, TM::Watertight, 4)->Name("triangle/watertight/4");
BENCHMARK_TEMPLATE(triangle_packet, TM::Watertight, 8)->Name("triangle/watertight/8");
BENCHMARK_TEMPLATE(triangle_packet, TM::Plane, 1)->Name("triangle/plane/1");
BENCHMARK_TEMPLATE(triangle_packet, TM::Plane, 4)->Name("triangle/plane/4");
BENCHMARK_TEMPLATE(triangle_packet, TM::Plane, 8)->Name("triangle/plane/8");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Moeller, 1)->Name("triangle_1xM/moeller/1");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Moeller, 4)->Name("triangle_1xM/moeller/4");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Moeller, 8)->Name("triangle_1xM/moeller/8");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Watertight, 1)->Name("triangle_1xM/watertight/1");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Watertight, 4)->Name("triangle_1xM/watertight/4");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Watertight, 8)->Name("triangle_1xM/watertight/8");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Plane, 1)->Name("triangle_1xM/plane/1");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Plane, 4)->Name("triangle_1xM/plane/4");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Plane, 8)->Name("triangle_1xM/plane/8");
#if defined(__AVX512BW__)
BENCHMARK_TEMPLATE(triangle_packet, TM::Moeller, 16)->Name("triangle/moeller/16");
BENCHMARK_TEMPLATE(triangle_packet, TM::Watertight, 16)->Name("triangle/watertight/16");
BENCHMARK_TEMPLATE(triangle_packet, TM::Plane, 16)->Name("triangle/plane/16");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Moeller, 16)->Name("triangle_1xM/moeller/16");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Watertight, 16)->Name("triangle_1xM/watertight/16");
BENCHMARK_TEMPLATE(triangle_1xM, TM::Plane, 16)->Name("triangle_1xM/plane/16");
#endif

}  // namespace
}  // namespace raypack::bench
