// Ray-triangle microbenchmarks: triangle/VARIANT/K (K rays against one
// triangle) and triangle_1xM/VARIANT/M (one ray against a block of M
// triangles in SoA). Every hit is kept (selected into running values), as a
// closest-hit loop would, so no output is dead code: t, u, v, or for Moeller
// t and the undivided U, V with 1/det, multiplied into u, v once at the end
// (kernels/triangle.h, MoellerUV). Every width runs the same loop.
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

/// What the closest-hit loop keeps of a test: t with u, v, or with
/// Moeller's deferred MoellerUV.
template <TriangleMethod M, class F>
struct KeptHit {
    F t = F(0.0f), u = F(0.0f), v = F(0.0f);
    RAYPACK_INLINE F final_u() const { return u; }
    RAYPACK_INLINE F final_v() const { return v; }
    /// Each hit lane overwrites its running values (which consumes the mask too).
    RAYPACK_INLINE void keep(const mask_of<F>& m, const KeptHit& h) {
        t = select(m, h.t, t);
        u = select(m, h.u, u);
        v = select(m, h.v, v);
    }
};
template <class F>
struct KeptHit<TriangleMethod::Moeller, F> {
    F t = F(0.0f);
    MoellerUV<F> uv{F(0.0f), F(0.0f), F(0.0f)};
    RAYPACK_INLINE F final_u() const { return uv.u(); }
    RAYPACK_INLINE F final_v() const { return uv.v(); }
    RAYPACK_INLINE void keep(const mask_of<F>& m, const KeptHit& h) {
        t = select(m, h.t, t);
        uv.U = select(m, h.uv.U, uv.U);
        uv.V = select(m, h.uv.V, uv.V);
        uv.inv_det = select(m, h.uv.inv_det, uv.inv_det);
    }
};

template <TriangleMethod M, class F>
RAYPACK_INLINE mask_of<F> tri_test(const PreparedRay<M, F>& r, const Vec3<F>& p0, const Vec3<F>& p1,
                                   const Vec3<F>& p2, KeptHit<M, F>& h) {
    const mask_of<F> all(true);
    if constexpr (M == TriangleMethod::Moeller)
        return intersect_triangle_moeller<F>(all, r.org, r.dir, r.tnear, r.tfar, p0, p1, p2, h.t, h.uv);
    else if constexpr (M == TriangleMethod::Watertight)
        return intersect_triangle_watertight<F>(all, r.ray, r.tnear, r.tfar, p0, p1, p2, h.t, h.u, h.v);
    else
        return intersect_triangle_plane<F>(all, r.org, r.dir, r.tnear, r.tfar, p0, p1, p2, h.t, h.u, h.v);
}

/// Publishes the final t, u, v of the running hits: DoNotOptimize on the
/// running values themselves would give them a home in memory, stored to
/// on every iteration.
template <TriangleMethod M, class F>
RAYPACK_INLINE void publish(const KeptHit<M, F>& h) {
    F t = h.t, u = h.final_u(), v = h.final_v();
    benchmark::DoNotOptimize(t);
    benchmark::DoNotOptimize(u);
    benchmark::DoNotOptimize(v);
}

bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

/// Lane l of a packet answer equals the width-1 answer: the same hit, and on
/// a hit the same t, u, v bit for bit.
template <TriangleMethod M, class F>
bool lane_matches(const mask_of<F>& m, const KeptHit<M, F>& h, int l, bool hit1, const KeptHit<M, float>& h1) {
    if (lane(m, l) != hit1) return false;
    return !hit1 || (same_bits(lane(h.t, l), h1.t) && same_bits(lane(h.final_u(), l), h1.final_u()) &&
                     same_bits(lane(h.final_v(), l), h1.final_v()));
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
        KeptHit<M, F> h;
        const mask_of<F> m = tri_test<M, F>(packets[i / K], p0, p1, p2, h);
        for (int l = 0; l < K; ++l) {
            KeptHit<M, float> h1;
            const bool hit1 =
                tri_test<M, float>(prepare<M>(load_rays<float>(rays, i + std::size_t(l))), kP0, kP1, kP2, h1);
            same &= lane_matches(m, h, l, hit1, h1);
            hits += hit1;
        }
    }
    if (!validated(state, same && hits > 0 && hits < rays.n, "packet lanes differ from the width-1 triangle test"))
        return;
    for (auto _ : state) {
        KeptHit<M, F> kept;
        for (const auto& r : packets) {
            KeptHit<M, F> h;
            kept.keep(tri_test<M, F>(r, p0, p1, p2, h), h);
        }
        publish(kept);
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
        KeptHit<M, F> h;
        const mask_of<F> m = tri_test<M, F>(broadcast[i], p0, p1, p2, h);
        const PreparedRay<M, float> r = prepare<M>(load_rays<float>(rays, i));
        for (int j = 0; j < Width; ++j) {
            KeptHit<M, float> h1;
            const bool hit1 = tri_test<M, float>(r, b.p(j, 0), b.p(j, 1), b.p(j, 2), h1);
            same &= lane_matches(m, h, j, hit1, h1);
            hits += hit1;
        }
    }
    if (!validated(state, same && hits > 0 && hits < rays.n * Width, "block lanes differ from the width-1 triangle test"))
        return;
    for (auto _ : state) {
        KeptHit<M, F> kept;
        for (const auto& r : broadcast) {
            KeptHit<M, F> h;
            kept.keep(tri_test<M, F>(r, p0, p1, p2, h), h);
        }
        publish(kept);
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
