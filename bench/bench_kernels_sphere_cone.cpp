// Sphere and cone microbenchmarks: sphere/VARIANT/K and cone/nff/K (K rays
// against one primitive), sphere_1xM/VARIANT/M and cone_1xM/nff/M (one ray
// against a block of M primitives in SoA). Each lane's hit and t are checked
// bit for bit against the width-1 kernel before timing.
#include <bit>
#include <cstring>

#include "bench/kernel_bench.h"
#include "kernels/cone.h"
#include "kernels/sphere.h"

namespace raypack::bench {
namespace {

// 512 rays x 40 bytes (QuadricRay) stay in L1, so the loop measures the
// kernel, not memory.
constexpr std::size_t kRays = 512;

// Shapes around the origin that about half of make_rays() hit.
const Vec3f kCenter{0.02f, -0.03f, 0.05f};
constexpr float kRadius = 0.4f;
const Vec3f kBase{-0.05f, -0.45f, 0.1f}, kApex{0.05f, 0.45f, -0.1f};
constexpr float kBaseRadius = 0.35f, kApexRadius = 0.15f;

/// One primitive, or a block of them, in lanes of F.
template <class F>
struct SphereLanes {
    Vec3<F> center;
    F radius;
};

/// The result of one kernel call: the hit lanes as bits, and t (and for the
/// cone s_frac) on those lanes.
template <class F>
struct Result {
    std::uint32_t bits;
    F t, s;
};

template <SphereMethod M>
struct SphereVariant {
    static constexpr SphereMethod method = M;
};

template <class Variant, class F>
RAYPACK_INLINE Result<F> run(const QuadricRay<F>& r, const SphereLanes<F>& s) {
    Result<F> out{};
    const mask_of<F> hit = intersect_sphere<Variant::method, F>(mask_of<F>(true), r, s.center, s.radius, out.t);
    out.bits = mask_bits(hit);
    out.t = select(hit, out.t, F(0.0f));
    out.s = F(0.0f);
    return out;
}

struct NffCone {};  // the only cone variant

template <class Variant, class F>
RAYPACK_INLINE Result<F> run(const QuadricRay<F>& r, const ConeLanes<F>& c) {
    Result<F> out{};
    const mask_of<F> hit = intersect_cone<F>(mask_of<F>(true), r, c, out.t, out.s);
    out.bits = mask_bits(hit);
    out.t = select(hit, out.t, F(0.0f));
    out.s = select(hit, out.s, F(0.0f));
    return out;
}

/// What the timed loops consume of a call: the hit lanes, and t (plus s_frac
/// for cones) in `value`, so that nothing the kernel computes is dead code.
template <class Variant, class F>
RAYPACK_INLINE mask_of<F> hot(const QuadricRay<F>& r, const SphereLanes<F>& s, F& value) {
    return intersect_sphere<Variant::method, F>(mask_of<F>(true), r, s.center, s.radius, value);
}

template <class Variant, class F>
RAYPACK_INLINE mask_of<F> hot(const QuadricRay<F>& r, const ConeLanes<F>& c, F& value) {
    F s_frac(0.0f);
    const mask_of<F> hit = intersect_cone<F>(mask_of<F>(true), r, c, value, s_frac);
    value = value + s_frac;
    return hit;
}

/// The quadric view of rays i .. i+lanes-1 (or of ray i broadcast): |dir|^2
/// and its reciprocal are part of the per-ray precomputation, like rdir for
/// the slab test.
template <class F>
QuadricRay<F> quadric_rays(const RayLanes<F>& r) {
    return make_quadric_ray<F>(r.org, r.dir, r.tnear, r.tfar);
}

/// One ray in every lane.
template <class F>
RAYPACK_INLINE QuadricRay<F> broadcast(const QuadricRay<float>& r) {
    return {{F(r.org.x), F(r.org.y), F(r.org.z)}, {F(r.dir.x), F(r.dir.y), F(r.dir.z)}, F(r.tnear), F(r.tfar),
            F(r.dd), F(r.inv_dd)};
}

bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

/// Lane l of a K-wide result equals a width-1 result, bit for bit.
template <class F>
bool lane_equals(const Result<F>& wide, int l, const Result<float>& one) {
    return ((wide.bits >> l) & 1u) == one.bits && same_bits(lane(wide.t, l), one.t) && same_bits(lane(wide.s, l), one.s);
}

/// A primitive of the kind P in lanes of F, from per-lane scalar primitives.
template <class F>
SphereLanes<F> sphere_lanes(const std::vector<SphereLanes<float>>& s) {
    alignas(64) float f[4][16];
    for (std::size_t j = 0; j < s.size(); ++j) {
        f[0][j] = s[j].center.x, f[1][j] = s[j].center.y, f[2][j] = s[j].center.z, f[3][j] = s[j].radius;
    }
    return {{load_lanes<F>(f[0]), load_lanes<F>(f[1]), load_lanes<F>(f[2])}, load_lanes<F>(f[3])};
}

template <class F>
ConeLanes<F> cone_lanes(const std::vector<ConeLanes<float>>& c) {
    alignas(64) float f[14][16];
    for (std::size_t j = 0; j < c.size(); ++j) {
        const ConeLanes<float>& x = c[j];
        const float v[14] = {x.base.x, x.base.y, x.base.z, x.w.x, x.w.y, x.w.z, x.mid.x,
                             x.mid.y,  x.mid.z,  x.h,      x.inv_h, x.k, x.rb, 0.0f};
        for (int i = 0; i < 14; ++i) f[i][j] = v[i];
    }
    ConeLanes<F> out;
    out.base = {load_lanes<F>(f[0]), load_lanes<F>(f[1]), load_lanes<F>(f[2])};
    out.w = {load_lanes<F>(f[3]), load_lanes<F>(f[4]), load_lanes<F>(f[5])};
    out.mid = {load_lanes<F>(f[6]), load_lanes<F>(f[7]), load_lanes<F>(f[8])};
    out.h = load_lanes<F>(f[9]);
    out.inv_h = load_lanes<F>(f[10]);
    out.k = load_lanes<F>(f[11]);
    out.rb = load_lanes<F>(f[12]);
    return out;
}

/// M primitives around the origin, scaled and shifted so that they differ
/// (the first is the unshifted one that the packet benchmarks use).
std::vector<SphereLanes<float>> make_spheres(int m) {
    std::vector<SphereLanes<float>> s;
    for (int j = 0; j < m; ++j) {
        const float scale = 1.0f - 0.1f * float(j % 5), dx = 0.1f * float((j + 1) % 3) - 0.1f;
        s.push_back({{kCenter.x + dx, kCenter.y - 0.05f * float(j % 2), kCenter.z + 0.1f * float(j % 4)}, kRadius * scale});
    }
    return s;
}

std::vector<ConeLanes<float>> make_cones(int m) {
    std::vector<ConeLanes<float>> c;
    for (int j = 0; j < m; ++j) {
        const float scale = 1.0f - 0.1f * float(j % 5), dx = 0.1f * float((j + 1) % 3) - 0.1f;
        const Vec3f shift{dx, 0.0f, 0.1f * float(j % 4)};
        c.push_back(make_cone<float>(kBase + shift, kBaseRadius * scale, kApex + shift, kApexRadius * scale));
    }
    return c;
}

template <class Prim>
std::vector<Prim> make_prims(int m) {
    if constexpr (std::is_same_v<Prim, SphereLanes<float>>) return make_spheres(m);
    else return make_cones(m);
}

template <class F, class Prim>
auto prim_lanes(const std::vector<Prim>& p) {
    if constexpr (std::is_same_v<Prim, SphereLanes<float>>) return sphere_lanes<F>(p);
    else return cone_lanes<F>(p);
}

/// KERNEL/VARIANT/K: K rays against one primitive.
template <class Variant, class Prim, int K>
void packet_bench(benchmark::State& state) {
    using F = vfloat<K>;
    const RaySoA rays = make_rays(kRays);
    const std::vector<Prim> one = make_prims<Prim>(1);
    const auto prim = prim_lanes<F>(std::vector<Prim>(K, one[0]));
    std::vector<QuadricRay<F>> packets;
    for (std::size_t i = 0; i < rays.n; i += K) packets.push_back(quadric_rays(load_rays<F>(rays, i)));
    std::size_t hits = 0;
    bool same = true;
    for (std::size_t i = 0; i < rays.n; i += K) {
        const Result<F> wide = run<Variant, F>(packets[i / K], prim);
        for (int l = 0; l < K; ++l) {
            const Result<float> scalar =
                run<Variant, float>(quadric_rays(load_rays<float>(rays, i + std::size_t(l))), one[0]);
            same &= lane_equals(wide, l, scalar);
            hits += scalar.bits;
        }
    }
    if (!validated(state, same && hits > rays.n / 4 && hits < rays.n * 3 / 4,
                   "packet lanes differ from the width-1 kernel (or hit rate off)"))
        return;
    for (auto _ : state) {
        std::uint32_t count = 0;
        F sum(0.0f);
        for (const QuadricRay<F>& p : packets) {
            F value(0.0f);
            const mask_of<F> hit = hot<Variant, F>(p, prim, value);
            count += std::popcount(mask_bits(hit));
            sum = sum + select(hit, value, F(0.0f));
        }
        benchmark::DoNotOptimize(count);
        const float total = lane(sum, 0);
        benchmark::DoNotOptimize(total);
    }
    set_tests_per_second(state, double(rays.n));
}

/// KERNEL_1xM/VARIANT/M: one ray against M primitives in SoA.
template <class Variant, class Prim, int Width>
void block_bench(benchmark::State& state) {
    using F = vfloat<Width>;
    const RaySoA rays = make_rays(kRays);
    const std::vector<Prim> prims = make_prims<Prim>(Width);
    const auto block = prim_lanes<F>(prims);
    // One QuadricRay<float> per ray (20 KB, in L1), broadcast at the call: a
    // vbroadcastss per field, or an embedded broadcast operand.
    std::vector<QuadricRay<float>> single;
    for (std::size_t i = 0; i < rays.n; ++i) single.push_back(quadric_rays(load_rays<float>(rays, i)));
    bool same = true;
    std::size_t hits = 0;
    for (std::size_t i = 0; i < rays.n; ++i) {
        const Result<F> wide = run<Variant, F>(broadcast<F>(single[i]), block);
        const QuadricRay<float> r = quadric_rays(load_rays<float>(rays, i));
        for (int j = 0; j < Width; ++j) {
            const Result<float> scalar = run<Variant, float>(r, prims[std::size_t(j)]);
            same &= lane_equals(wide, j, scalar);
            hits += scalar.bits;
        }
    }
    if (!validated(state, same && hits > rays.n * Width / 5 && hits < rays.n * Width * 4 / 5,
                   "block lanes differ from the width-1 kernel (or hit rate off)"))
        return;
    for (auto _ : state) {
        std::uint32_t count = 0;
        F sum(0.0f);
        for (const QuadricRay<float>& r : single) {
            F value(0.0f);
            const mask_of<F> hit = hot<Variant, F>(broadcast<F>(r), block, value);
            count += std::popcount(mask_bits(hit));
            sum = sum + select(hit, value, F(0.0f));
        }
        benchmark::DoNotOptimize(count);
        const float total = lane(sum, 0);
        benchmark::DoNotOptimize(total);
    }
    set_tests_per_second(state, double(rays.n) * Width);
}

using Sph = SphereLanes<float>;
using Cone = ConeLanes<float>;
using Alg = SphereVariant<SphereMethod::Algebraic>;
using Geo = SphereVariant<SphereMethod::Geometric>;
using Pre = SphereVariant<SphereMethod::Precise>;

#define PACKET(V, P, NAME, K) BENCHMARK_TEMPLATE(packet_bench, V, P, K)->Name(NAME "/" #K)
#define BLOCK(V, P, NAME, K) BENCHMARK_TEMPLATE(block_bench, V, P, K)->Name(NAME "/" #K)
#if defined(__AVX512BW__)
#define AT_EVERY_WIDTH(WHAT, V, P, NAME) \
    WHAT(V, P, NAME, 1);                 \
    WHAT(V, P, NAME, 4);                 \
    WHAT(V, P, NAME, 8);                 \
    WHAT(V, P, NAME, 16)
#else
#define AT_EVERY_WIDTH(WHAT, V, P, NAME) \
    WHAT(V, P, NAME, 1);                 \
    WHAT(V, P, NAME, 4);                 \
    WHAT(V, P, NAME, 8)
#endif

AT_EVERY_WIDTH(PACKET, Alg, Sph, "sphere/algebraic");
AT_EVERY_WIDTH(PACKET, Geo, Sph, "sphere/geometric");
AT_EVERY_WIDTH(PACKET, Pre, Sph, "sphere/precise");
AT_EVERY_WIDTH(PACKET, NffCone, Cone, "cone/nff");
AT_EVERY_WIDTH(BLOCK, Alg, Sph, "sphere_1xM/algebraic");
AT_EVERY_WIDTH(BLOCK, Geo, Sph, "sphere_1xM/geometric");
AT_EVERY_WIDTH(BLOCK, Pre, Sph, "sphere_1xM/precise");
AT_EVERY_WIDTH(BLOCK, NffCone, Cone, "cone_1xM/nff");

}  // namespace
}  // namespace raypack::bench
