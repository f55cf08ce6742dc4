#pragma once
// cos^n of the Phong highlight, in float lanes or a plain float with the same
// operations in the same order, so that the SIMD light loops and the scalar
// shading give the same bits (libm's powf, called lane by lane, was 3% of a
// Whitted render of the teapot).
//
// Method: exp2(n log2 x). log2 from Cephes' logf (Moshier: the exponent, and
// a degree-9 polynomial of the mantissa folded into [sqrt(1/2), sqrt(2))),
// exp2 from Cephes' exp2f (the nearest integer, and a degree-6 polynomial
// of the rest in [-1/2, 1/2]); results below 2^-125 are +0. Relative error
// about n |log2 x| 2^-23 (a highlight's exponent magnifies log2's error):
// far below what an 8-bit pixel shows.
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "kernels/simd.h"

namespace raypack {

namespace phong_power_detail {
RAYPACK_INLINE std::int32_t bits_of(float x) { return std::bit_cast<std::int32_t>(x); }
RAYPACK_INLINE float float_of(std::int32_t i) { return std::bit_cast<float>(i); }
RAYPACK_INLINE float to_float(std::int32_t i) { return float(i); }
RAYPACK_INLINE std::int32_t to_int(float x) { return std::int32_t(x); }  // exact: x is integral
template <class A>
RAYPACK_INLINE auto bits_of(const xsimd::batch<float, A>& x) {
    return xsimd::bitwise_cast<xsimd::batch<std::int32_t, A>>(x);
}
template <class A>
RAYPACK_INLINE auto float_of(const xsimd::batch<std::int32_t, A>& i) {
    return xsimd::bitwise_cast<xsimd::batch<float, A>>(i);
}
template <class A>
RAYPACK_INLINE auto to_float(const xsimd::batch<std::int32_t, A>& i) {
    return xsimd::to_float(i);
}
template <class A>
RAYPACK_INLINE auto to_int(const xsimd::batch<float, A>& x) {
    return xsimd::to_int(x);
}
}  // namespace phong_power_detail

/// x^n for 0 < x <= 1 and n >= 0: +0 where it is below 2^-125 (and for x
/// below the normal floats, unless n = 0). F is float or a float batch;
/// both compute the same bits.
template <class F>
RAYPACK_INLINE F phong_power(F x, F n) {
    using namespace phong_power_detail;
    using I = decltype(bits_of(x));
    // x = m 2^e with m in [1/2, 1).
    const I bits = bits_of(x);
    const F e = to_float((bits >> 23) - I(126));
    F m = float_of((bits & I(0x007FFFFF)) | I(0x3F000000));
    // Fold m into [sqrt(1/2), sqrt(2)), less 1.
    const auto small = m < F(0.707106781186547524f);
    const F fe = select(small, e - F(1.0f), e);
    m = select(small, m + m - F(1.0f), m - F(1.0f));
    const F z = m * m;
    F y = ((((((((F(7.0376836292e-2f) * m + F(-1.1514610310e-1f)) * m + F(1.1676998740e-1f)) * m +
                F(-1.2420140846e-1f)) * m + F(1.4249322787e-1f)) * m + F(-1.6668057665e-1f)) * m +
             F(2.0000714765e-1f)) * m + F(-2.4999993993e-1f)) * m + F(3.3333331174e-1f)) * m * z;
    y = y + F(-2.12194440e-4f) * fe;
    y = y - F(0.5f) * z;
    const F ln = (m + y) + F(0.693359375f) * fe;
    // t = n log2 x <= 0; 2^t = 2^i 2^f with i the nearest integer, i >= -125
    // so that 2^i times f's 2^f (at least 2^-1/2) is still a normal float.
    const F t = n * (ln * F(std::numbers::log2e_v<float>));
    const auto zero = (t < F(-125.0f)) || ((x < F(0x1.0p-126f)) && (n > F(0.0f)));
    const F tc = select(zero, F(0.0f), t);
    const F i = round_nearest(tc);
    const F f = tc - i;
    const F p = F(1.0f) + f * (((((F(1.535336188319500e-4f) * f + F(1.339887440266574e-3f)) * f +
                                  F(9.618437357674640e-3f)) * f + F(5.550332471162809e-2f)) * f +
                                F(2.402264791363012e-1f)) * f + F(6.931472028550421e-1f));
    const F scaled = float_of(bits_of(p) + (to_int(i) << 23));
    return select(zero, F(0.0f), scaled);
}

}  // namespace raypack
