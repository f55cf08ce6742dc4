#pragma once
// Scalar ray test for NFF's truncated cone: radius rb at the base, ra at the
// apex, varying linearly along the axis, open at both ends (no caps).
#include "kernels/quadratic.h"
#include "kernels/ray.h"

namespace raypack {

/// A point at axial distance s from the base lies on the surface when its
/// distance from the axis equals r(s) = rb + k s with k = (ra - rb) / h.
/// Substituting the ray gives a quadratic in t; roots whose s falls outside
/// [0, h] are discarded. On a hit, `s_frac` = s / h (0 at the base).
template <class T>
bool intersect_cone(const Ray<T>& ray, const Vec3<T>& base, T base_radius, const Vec3<T>& apex, T apex_radius,
                    T& t, T& s_frac) {
    const Vec3<T> axis = apex - base;
    const T h = length(axis);
    const Vec3<T> w = axis / h;
    const T k = (apex_radius - base_radius) / h;
    // Move the origin to the ray's closest approach to the cone's middle
    // first: for a thin cone seen from afar, |co|^2 - r0^2 would otherwise
    // lose r0^2 to cancellation (the re-centring of Haines et al., "Precision
    // Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7).
    const T dd = dot(ray.dir, ray.dir);
    const T t_mid = dot((base + apex) * T(0.5) - ray.org, ray.dir) / dd;
    const Vec3<T> co = ray.org + ray.dir * t_mid - base;
    // Work with the components perpendicular to the axis, so that nothing
    // large is squared and then subtracted.
    const T s0 = dot(co, w);         // axial position of the (moved) origin
    const T ds = dot(ray.dir, w);    // axial speed
    const Vec3<T> co_perp = co - w * s0;
    const Vec3<T> d_perp = ray.dir - w * ds;
    const T r0 = base_radius + k * s0;
    const T a = dot(d_perp, d_perp) - k * k * ds * ds;
    const T b = dot(co_perp, d_perp) - r0 * k * ds;
    const T c = dot(co_perp, co_perp) - r0 * r0;
    T t0, t1;
    if (!solve_quadratic_half(a, b, c, t0, t1)) return false;
    const T roots[2] = {t0, t1};
    for (T tr : roots) {
        const T tt = t_mid + tr;
        if (!(tt >= ray.tnear && tt <= ray.tfar)) continue;
        const T s = s0 + tr * ds;
        if (s >= T(0) && s <= h && base_radius + k * s >= T(0)) {
            t = tt;
            s_frac = s / h;
            return true;
        }
    }
    return false;
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
