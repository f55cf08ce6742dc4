#pragma once
// Roots of a t^2 + 2 b t + c = 0 (note the half linear coefficient), and the
// lane-generic pieces the sphere and cone kernels share. The lane helpers
// accept long double as well (scalar, for high-precision references in tests).
#include <cmath>
#include <type_traits>
#include <utility>

#include "kernels/fused.h"
#include "kernels/simd.h"
#include "kernels/vec3.h"

namespace raypack {


/// What the sphere and cone tests need of a ray, computed once per ray like
/// the slab test's reciprocal direction: |dir|^2 (the t^2 coefficient of
/// every quadric) and its reciprocal, so that the kernels need not divide by it.
template <class F>
struct QuadricRay {
    Vec3<F> org, dir;
    F tnear, tfar;
    F dd;      ///< dir . dir
    F inv_dd;  ///< 1 / (dir . dir)
};

template <class F>
RAYPACK_INLINE QuadricRay<F> make_quadric_ray(const Vec3<F>& org, const Vec3<F>& dir, const F& tnear, const F& tfar) {
    const F dd = fused_dot(dir, dir);
    return {org, dir, tnear, tfar, dd, F(1) / dd};
}

/// The nearer of two roots lo <= hi inside [tnear, tfar]: narrows `valid` to
/// the lanes that have one and writes it to `t` (every lane; meaningful on
/// the returned ones). NaN roots are never inside. lo is the answer if it is
/// past tnear (then hi, further still, cannot be in when lo is past tfar);
/// otherwise hi is.
template <class F>
RAYPACK_INLINE mask_of<F> nearest_root(mask_of<F> valid, const F& lo, const F& hi, const F& tnear, const F& tfar, F& t) {
    t = select(lo >= tnear, lo, hi);
    return valid & (t >= tnear) & (t <= tfar);
}

/// Numerically stable roots (Press et al., Numerical Recipes 5.6): the root
/// that would suffer cancellation is taken from the product of the roots.
/// Returns false when there is no real root; otherwise t0 <= t1.
template <class T>
bool solve_quadratic_half(T a, T b, T c, T& t0, T& t1) {
    const T disc = b * b - a * c;
    if (!(disc >= T(0)) || a == T(0)) return false;
    const T root = std::sqrt(disc);
    const T q = b >= T(0) ? -(b + root) : -(b - root);
    if (q == T(0)) {  // b == 0 and c == 0: both roots at 0
        t0 = t1 = T(0);
        return true;
    }
    t0 = q / a;
    t1 = c / q;
    if (t0 > t1) std::swap(t0, t1);
    return true;
}

/// The nearer of two sorted roots inside [tnear, tfar], if any.
template <class T>
bool nearest_root_in(T t0, T t1, T tnear, T tfar, T& t) {
    if (t0 >= tnear && t0 <= tfar) { t = t0; return true; }
    if (t1 >= tnear && t1 <= tfar) { t = t1; return true; }
    return false;
}

}  // namespace raypack
