#pragma once
// Roots of a t^2 + 2 b t + c = 0 (note the half linear coefficient), and the
// lane-generic pieces the sphere and cone kernels share. The lane helpers
// accept long double as well (scalar, for high-precision references in tests).
#include <cmath>
#include <type_traits>
#include <utility>

#include "kernels/simd.h"
#include "kernels/vec3.h"

namespace raypack {

namespace lanes {

template <class F> struct MaskType { using type = mask_of<F>; };
template <> struct MaskType<long double> { using type = bool; };

/// Mask of lane type F: bool for float, double and long double.
template <class F> using Mask = typename MaskType<F>::type;

template <class F>
RAYPACK_INLINE F fma(const F& a, const F& b, const F& c) {
    if constexpr (std::is_same_v<F, long double>) return std::fma(a, b, c);
    else return vfmadd(a, b, c);
}
/// c - a * b and a * b - c with one rounding: the same values as fma(-a, b, c)
/// and fma(a, b, -c), without the negation (vfnmadd / vfmsub).
template <class F>
RAYPACK_INLINE F fnma(const F& a, const F& b, const F& c) {
    if constexpr (std::is_floating_point_v<F>) return std::fma(-a, b, c);
    else if constexpr (sizeof(F) == 16) return _mm_fnmadd_ps(a, b, c);
    else if constexpr (sizeof(F) == 32) return _mm256_fnmadd_ps(a, b, c);
#if defined(__AVX512F__)
    else if constexpr (sizeof(F) == 64) return _mm512_fnmadd_ps(a, b, c);
#endif
    else static_assert(sizeof(F) == 0, "fnma: unsupported width");
}
template <class F>
RAYPACK_INLINE F fms(const F& a, const F& b, const F& c) {
    if constexpr (std::is_floating_point_v<F>) return std::fma(a, b, -c);
    else if constexpr (sizeof(F) == 16) return _mm_fmsub_ps(a, b, c);
    else if constexpr (sizeof(F) == 32) return _mm256_fmsub_ps(a, b, c);
#if defined(__AVX512F__)
    else if constexpr (sizeof(F) == 64) return _mm512_fmsub_ps(a, b, c);
#endif
    else static_assert(sizeof(F) == 0, "fms: unsupported width");
}
template <class F>
RAYPACK_INLINE F sqrt(const F& x) {
    if constexpr (std::is_same_v<F, long double>) return std::sqrt(x);
#if defined(__AVX512F__)
    // gcc 12's _mm512_sqrt_ps passes _mm512_undefined_ps() through, which
    // -Wmaybe-uninitialized reports; the all-lanes masked form is the same
    // instruction.
    else if constexpr (sizeof(F) == 64) return _mm512_mask_sqrt_ps(x, __mmask16(0xFFFF), x);
#endif
    else return vsqrt(x);
}
template <class F>
RAYPACK_INLINE F copysign(const F& x, const F& s) {
    if constexpr (std::is_same_v<F, long double>) return std::copysign(x, s);
    else return copysign_of(x, s);
}

/// a . b as one multiply and two fused multiply-adds (one instruction fewer
/// than three products and two sums, and no rounding of two of the products).
template <class F>
RAYPACK_INLINE F dot(const Vec3<F>& a, const Vec3<F>& b) {
    return lanes::fma(a.x, b.x, lanes::fma(a.y, b.y, a.z * b.z));
}

/// a - b * s, per component, fused.
template <class F>
RAYPACK_INLINE Vec3<F> sub_scaled(const Vec3<F>& a, const Vec3<F>& b, const F& s) {
    return {lanes::fnma(b.x, s, a.x), lanes::fnma(b.y, s, a.y), lanes::fnma(b.z, s, a.z)};
}

template <class F>
RAYPACK_INLINE Vec3<F> sub(const Vec3<F>& a, const Vec3<F>& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}

}  // namespace lanes

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
    const F dd = lanes::dot(dir, dir);
    return {org, dir, tnear, tfar, dd, F(1) / dd};
}

namespace lanes {

/// The nearer of two roots lo <= hi inside [tnear, tfar]: narrows `valid` to
/// the lanes that have one and writes it to `t` (every lane; meaningful on
/// the returned ones). NaN roots are never inside. lo is the answer if it is
/// past tnear (then hi, further still, cannot be in when lo is past tfar);
/// otherwise hi is.
template <class F>
RAYPACK_INLINE Mask<F> nearest_root(Mask<F> valid, const F& lo, const F& hi, const F& tnear, const F& tfar, F& t) {
    t = select(lo >= tnear, lo, hi);
    return valid & (t >= tnear) & (t <= tfar);
}

}  // namespace lanes

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
