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
    const Vec3<T> co = ray.org - base;
    const T s0 = dot(co, w);        // axial position of the origin
    const T ds = dot(ray.dir, w);   // axial speed
    const T r0 = base_radius + k * s0;
    const T a = dot(ray.dir, ray.dir) - ds * ds - k * k * ds * ds;
    const T b = dot(co, ray.dir) - s0 * ds - r0 * k * ds;
    const T c = dot(co, co) - s0 * s0 - r0 * r0;
    T t0, t1;
    if (!solve_quadratic_half(a, b, c, t0, t1)) return false;
    const T roots[2] = {t0, t1};
    for (T tr : roots) {
        if (!(tr >= ray.tnear && tr <= ray.tfar)) continue;
        const T s = s0 + tr * ds;
        if (s >= T(0) && s <= h && base_radius + k * s >= T(0)) {
            t = tr;
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
