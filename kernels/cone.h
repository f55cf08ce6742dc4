#pragma once
// Ray test for NFF's truncated cone: radius rb at the base, ra at the apex,
// varying linearly along the axis, open at both ends (no caps). Written once
// for every lane type (kernels/simd.h): K rays against one cone, or one ray
// against K cones stored as SoA (ConeLanes, precomputed once per cone).
#include "kernels/quadratic.h"
#include "kernels/ray.h"

namespace raypack {

/// What the cone test needs of a cone, computed once per cone (per lane).
template <class F>
struct ConeLanes {
    Vec3<F> base;  ///< centre of the base disc
    Vec3<F> w;     ///< unit axis, base to apex
    Vec3<F> mid;   ///< midpoint of the axis
    F h;           ///< height |apex - base|
    F inv_h;       ///< 1 / h
    F k;           ///< radius slope (ra - rb) / h
    F rb;          ///< base radius
};

template <class F>
RAYPACK_INLINE ConeLanes<F> make_cone(const Vec3<F>& base, const F& base_radius, const Vec3<F>& apex,
                                      const F& apex_radius) {
    const Vec3<F> axis = (apex - base);
    ConeLanes<F> c;
    c.base = base;
    c.h = vsqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
    c.w = {axis.x / c.h, axis.y / c.h, axis.z / c.h};
    c.mid = {(base.x + apex.x) * F(0.5), (base.y + apex.y) * F(0.5), (base.z + apex.z) * F(0.5)};
    c.inv_h = F(1) / c.h;
    c.k = (apex_radius - base_radius) / c.h;
    c.rb = base_radius;
    return c;
}

/// A point at axial distance s from the base lies on the surface when its
/// distance from the axis equals r(s) = rb + k s. Substituting the ray gives a
/// quadratic in t; roots whose s falls outside [0, h] are discarded (and so
/// is the mirrored nappe, r(s) < 0). Returns the lanes of `valid` that hit
/// within [tnear, tfar], with the nearest such t in `t` and s / h (0 at the
/// base) in `s_frac`, meaningful on those lanes only. A ray parallel to a
/// generator line crosses the surface once; one along a cylinder's axis
/// never does.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_cone(mask_of<F> valid, const QuadricRay<F>& ray, const ConeLanes<F>& cone,
                                             F& t, F& s_frac) {
    const Vec3<F>& org = ray.org;
    const Vec3<F>& dir = ray.dir;
    // Move the origin to the ray's closest approach to the cone's middle
    // first: for a thin cone seen from afar, |co|^2 - r0^2 would otherwise
    // lose r0^2 to cancellation (the re-centring of Haines et al., "Precision
    // Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7).
    // Any t_mid near the projection works: the roots are relative to it.
    const F t_mid = fused_dot((cone.mid - org), dir) * ray.inv_dd;
    const Vec3<F> co = {vfmadd(dir.x, t_mid, org.x) - cone.base.x, vfmadd(dir.y, t_mid, org.y) - cone.base.y,
                        vfmadd(dir.z, t_mid, org.z) - cone.base.z};
    // Work with the components perpendicular to the axis, so that nothing
    // large is squared and then subtracted.
    const F s0 = fused_dot(co, cone.w);   // axial position of the (moved) origin
    const F ds = fused_dot(dir, cone.w);  // axial speed
    const Vec3<F> co_perp = fused_sub_scaled(co, cone.w, s0);
    const Vec3<F> d_perp = fused_sub_scaled(dir, cone.w, ds);
    const F r0 = vfmadd(cone.k, s0, cone.rb);
    const F kds = cone.k * ds;
    // a t^2 + 2 b t + c = 0 in t relative to t_mid.
    const F a = vfnmadd(kds, kds, fused_dot(d_perp, d_perp));
    const F b = vfnmadd(r0, kds, fused_dot(co_perp, d_perp));
    const F c = vfnmadd(r0, r0, fused_dot(co_perp, co_perp));
    const F disc = vfmsub(b, b, a * c);
    valid = valid & (disc >= F(0));
    if (none(valid)) return valid;
    // Stable root pair (Press et al., Numerical Recipes 5.6). q == 0 only
    // when b == 0 and c == 0 (double root at 0, with a != 0): c / q is then
    // NaN, and vmin/vmax, which return the second operand on NaN, give q / a
    // twice. a == 0 (parallel to a generator line) leaves the one crossing
    // c / q = -c / 2b and q / a = +-inf, which fails the end test; with
    // b == 0 as well (along a cylinder's axis) both are NaN.
    const F q = -(b + copysign_of(vsqrt(disc), b));
    const F t_q = q / a, t_c = c / q;
    const F lo = vmin(t_c, t_q), hi = vmax(t_c, t_q);
    // A root counts when it is within [tnear, tfar] and between the ends.
    const F t_lo = t_mid + lo, t_hi = t_mid + hi;
    const F s_lo = vfmadd(lo, ds, s0), s_hi = vfmadd(hi, ds, s0);
    const mask_of<F> in_lo = (t_lo >= ray.tnear) & (t_lo <= ray.tfar) & (s_lo >= F(0)) & (s_lo <= cone.h) &
                                 (vfmadd(cone.k, s_lo, cone.rb) >= F(0));
    const mask_of<F> in_hi = (t_hi >= ray.tnear) & (t_hi <= ray.tfar) & (s_hi >= F(0)) & (s_hi <= cone.h) &
                                 (vfmadd(cone.k, s_hi, cone.rb) >= F(0));
    t = select(in_lo, t_lo, t_hi);
    s_frac = select(in_lo, s_lo, s_hi) * cone.inv_h;
    return valid & (in_lo | in_hi);
}

/// The same from the ray's fields.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_cone(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                             const F& tnear, const F& tfar, const ConeLanes<F>& cone, F& t,
                                             F& s_frac) {
    return intersect_cone<F>(valid, make_quadric_ray<F>(org, dir, tnear, tfar), cone, t, s_frac);
}

/// The same from the ray's fields and the cone's end points.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_cone(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                             const F& tnear, const F& tfar, const Vec3<F>& base,
                                             const F& base_radius, const Vec3<F>& apex, const F& apex_radius, F& t,
                                             F& s_frac) {
    return intersect_cone<F>(valid, org, dir, tnear, tfar, make_cone<F>(base, base_radius, apex, apex_radius), t,
                             s_frac);
}

/// Scalar entry point: one ray, one cone; `t` and `s_frac` untouched on a miss.
template <class T>
bool intersect_cone(const Ray<T>& ray, const Vec3<T>& base, T base_radius, const Vec3<T>& apex, T apex_radius,
                    T& t, T& s_frac) {
    T tt, ss;
    if (!intersect_cone<T>(true, ray.org, ray.dir, ray.tnear, ray.tfar, make_cone<T>(base, base_radius, apex, apex_radius),
                           tt, ss))
        return false;
    t = tt;
    s_frac = ss;
    return true;
}

/// Outward normal (not normalised) at point p on the cone: the gradient of
/// |p - axis point|^2 - r(s)^2.
template <class T>
Vec3<T> cone_normal(const Vec3<T>& p, const Vec3<T>& base, T base_radius, const Vec3<T>& apex, T apex_radius) {
    const Vec3<T> axis = apex - base;
    const T h = length(axis);
    const Vec3<T> w = axis / h;
    const T k = (apex_radius - base_radius) / h;
    const T s = dot(p - base, w);
    const Vec3<T> perp = (p - base) - w * s;
    return perp - w * ((base_radius + k * s) * k);
}

}  // namespace raypack
