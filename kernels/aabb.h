#pragma once
// Axis-aligned boxes and the slab test (Kay & Kajiya 1986), written once for
// every lane type (see kernels/simd.h): K rays against one box, or one ray
// against K boxes stored as SoA.
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "kernels/ray.h"
#include "kernels/fused.h"
#include "kernels/simd.h"

namespace raypack {

template <class T>
struct Box3 {
    Vec3<T> lo{std::numeric_limits<T>::infinity(), std::numeric_limits<T>::infinity(),
               std::numeric_limits<T>::infinity()};
    Vec3<T> hi{-std::numeric_limits<T>::infinity(), -std::numeric_limits<T>::infinity(),
               -std::numeric_limits<T>::infinity()};

    void extend(const Vec3<T>& p) { lo = min(lo, p); hi = max(hi, p); }
    void extend(const Box3& b) { lo = min(lo, b.lo); hi = max(hi, b.hi); }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    Vec3<T> extent() const { return hi - lo; }
    Vec3<T> center() const { return (lo + hi) * T(0.5); }
    /// Half the surface area, the quantity the SAH compares.
    T half_area() const {
        if (empty()) return T(0);
        const Vec3<T> e = extent();
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
};

using Box3f = Box3<float>;

enum class SlabMethod { Plain, Robust };

/// gamma(n) of Higham / pbrt: bound on the relative error of n roundings.
template <class T>
constexpr T rounding_gamma(int n) {
    constexpr T eps = std::numeric_limits<T>::epsilon() / 2;
    return (T(n) * eps) / (T(1) - T(n) * eps);
}

/// Smallest direction magnitude the slab tests divide by. A zero or tiny
/// component becomes +-kMinRcpInput (keeping its sign), so the reciprocal is
/// finite: a ray on a slab plane then gives 0 * 1e18 = 0 instead of
/// 0 * inf = NaN, and rays parallel to a slab need no branch (as Embree does).
inline constexpr float kMinRcpInput = 1e-18f;

/// Reciprocal direction for the slab tests, for any lane type.
template <class F>
RAYPACK_INLINE Vec3<F> reciprocal(const Vec3<F>& d) {
    const F tiny(kMinRcpInput);
    auto safe = [&](const F& c) { return select(vabs(c) < tiny, copysign_of(tiny, c), c); };
    return {F(1) / safe(d.x), F(1) / safe(d.y), F(1) / safe(d.z)};
}

/// How reciprocal directions are computed (`--rcp`): exactly, by division,
/// or from the hardware estimate plus one Newton-Raphson step.
enum class RcpMethod { Exact, Approx };

/// 1/x from the hardware estimate (rcp14, 14 bits, with AVX-512; rcpss,
/// 12 bits, otherwise) refined by one Newton-Raphson step,
/// r1 = r0 + r0 (1 - x r0), as Embree's rcp() does: within a few ulps of
/// 1/x, not correctly rounded, so the robust slab test's widening by
/// 1 + 2 gamma(3) no longer covers every rounding (the trade --rcp measures).
inline float approx_reciprocal(float x) {
#if defined(__AVX512F__)
    const float r0 = _mm_cvtss_f32(_mm_rcp14_ss(_mm_setzero_ps(), _mm_set_ss(x)));
#else
    const float r0 = _mm_cvtss_f32(_mm_rcp_ss(_mm_set_ss(x)));
#endif
    return std::fma(r0, std::fma(-x, r0, 1.0f), r0);
}

/// reciprocal() by the method `--rcp` names; rays compute it once, at width 1,
/// so packets and single rays get the same bits either way.
inline Vec3f reciprocal(const Vec3f& d, RcpMethod method) {
    if (method == RcpMethod::Exact) return reciprocal(d);
    const float tiny = kMinRcpInput;
    auto safe = [&](float c) { return std::fabs(c) < tiny ? std::copysign(tiny, c) : c; };
    return {approx_reciprocal(safe(d.x)), approx_reciprocal(safe(d.y)), approx_reciprocal(safe(d.z))};
}

/// What a slab test needs of a ray: origin, reciprocal direction and, for the
/// plain test, origin * reciprocal direction, all computed once per ray.
template <class F>
struct SlabRay {
    Vec3<F> org, rdir, org_rdir;
    F tnear, tfar;
};

template <class F>
RAYPACK_INLINE SlabRay<F> make_slab_ray(const Vec3<F>& org, const Vec3<F>& rdir, const F& tnear, const F& tfar) {
    return {org, rdir, {org.x * rdir.x, org.y * rdir.y, org.z * rdir.z}, tnear, tfar};
}

/// Slab test of lanes of rays against lanes of boxes (either side may be
/// broadcast). Returns the lanes of `valid` whose ray meets the box within
/// [tnear, tfar]; `entry` gets the entry distance (clamped to tnear).
///
/// Plain, for speed: each plane distance is one fused multiply-add,
/// lo * rdir - org * rdir (Embree's form); a ray lying exactly in a slab
/// plane and parallel to it counts as leaving the slab at once, as in Embree.
///
/// Robust, for the reference path and wherever exactness matters:
/// - distances as (lo - org) * rdir, the far one widened by 1 + 2 gamma(3), so
///   that rounding never culls a box the exact ray touches, e.g. a ray aimed
///   exactly at a mesh vertex on the box's corner (Ize, "Robust BVH Ray
///   Traversal", JCGT 2013; pbrt-v4 Bounds3::IntersectP);
/// - a component reciprocal() clamped (a ray parallel to that slab) bounds
///   nothing: the ray is inside the slab for all t if its origin is within
///   [lo, hi], boundaries included, and nowhere otherwise.
template <SlabMethod Method, class F>
RAYPACK_INLINE mask_of<F> intersect_box(const mask_of<F>& valid, const SlabRay<F>& ray, const Vec3<F>& lo,
                                        const Vec3<F>& hi, F& entry) {
    const Vec3<F>& org = ray.org;
    const Vec3<F>& rdir = ray.rdir;
    F tx0, tx1, ty0, ty1, tz0, tz1;
    mask_of<F> ok = valid;
    if constexpr (Method == SlabMethod::Plain) {
        // Each is used twice: load once (see keep_in_register).
        Vec3<F> r = rdir, od = ray.org_rdir;
        keep_in_register(r), keep_in_register(od);
        tx0 = vfmsub(lo.x, r.x, od.x), tx1 = vfmsub(hi.x, r.x, od.x);
        ty0 = vfmsub(lo.y, r.y, od.y), ty1 = vfmsub(hi.y, r.y, od.y);
        tz0 = vfmsub(lo.z, r.z, od.z), tz1 = vfmsub(hi.z, r.z, od.z);
    } else {
        tx0 = (lo.x - org.x) * rdir.x, tx1 = (hi.x - org.x) * rdir.x;
        ty0 = (lo.y - org.y) * rdir.y, ty1 = (hi.y - org.y) * rdir.y;
        tz0 = (lo.z - org.z) * rdir.z, tz1 = (hi.z - org.z) * rdir.z;
        // Computed exactly as reciprocal() does, so a clamped component compares equal.
        const F huge = F(1) / F(kMinRcpInput), inf(std::numeric_limits<float>::infinity());
        auto parallel_axis = [&](const F& o, const F& r, const F& l, const F& h, F& t0, F& t1) {
            const auto parallel = vabs(r) >= huge;
            ok = ok & !(parallel & ((o < l) | (o > h)));
            t0 = select(parallel, -inf, t0);
            t1 = select(parallel, inf, t1);
        };
        parallel_axis(org.x, rdir.x, lo.x, hi.x, tx0, tx1);
        parallel_axis(org.y, rdir.y, lo.y, hi.y, ty0, ty1);
        parallel_axis(org.z, rdir.z, lo.z, hi.z, tz0, tz1);
    }
    const F t_in = vmax(vmax(vmin(tx0, tx1), vmin(ty0, ty1)), vmax(vmin(tz0, tz1), ray.tnear));
    F t_out = vmin(vmin(vmax(tx0, tx1), vmax(ty0, ty1)), vmax(tz0, tz1));
    t_out = vmin(t_out, ray.tfar);
    // Widened after the clamp: a hit exactly at tfar (tnear == tfar == t, or a
    // shadow ray ending on a surface) must not lose its box to the rounding of
    // the entry distance.
    if constexpr (Method == SlabMethod::Robust) t_out = t_out * F(1.0f + 2.0f * rounding_gamma<float>(3));
    entry = t_in;
    return ok & (t_in <= t_out);
}

/// Scalar form used by the reference traversal: robust, one ray, one box.
template <class T>
RAYPACK_INLINE bool intersect_aabb(const Vec3<T>& org, const Vec3<T>& inv_dir, const Box3<T>& box, T tnear, T tfar, T& entry) {
    const SlabRay<T> ray{org, inv_dir, {}, tnear, tfar};  // robust: org_rdir unused
    return intersect_box<SlabMethod::Robust, T>(true, ray, box.lo, box.hi, entry);
}

/// How far primitive boxes are widened before a group of rays, with
/// origins in [o_lo, o_hi], culls them by their boxes instead of testing
/// them: 2^-13 of the largest of the region's extent and its distance from
/// the origins. The boxes only stand in for the primitive tests, which are
/// not exact: Moeller's test may report a hit a little outside the triangle
/// (at grazing angles by about eps x distance / sin(angle)); so widened, a
/// box drops only hits the single ray would also have to find more than
/// 2^-13 x distance off the triangle, i.e. rays within about 0.03 degrees
/// of its plane. Used by the BVH's and the k-d tree's groups.
inline float culling_box_pad(const Box3f& region, const float (&o_lo)[3], const float (&o_hi)[3]) {
    float reach = 0.0f;
    for (int a = 0; a < 3; ++a)
        reach = std::max({reach, region.hi[a] - region.lo[a], std::fabs(region.hi[a] - o_lo[a]),
                          std::fabs(o_hi[a] - region.lo[a])});
    return reach * 0x1p-13f;
}

}  // namespace raypack
