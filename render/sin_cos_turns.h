#pragma once
// sin(2 pi u) and cos(2 pi u) of a fraction of a turn, in float lanes or a
// plain float with the same operations in the same order, so that a
// renderer's SIMD lanes and its scalar path draw the same directions bit for
// bit. Every warp that turns a uniform number into an angle (the polar disk,
// the Phong lobe's azimuth, a sphere light's cap) calls it: the libm calls it
// replaces ran one lane at a time (sincosf was 5% of a path-traced Cornell
// box).
//
// Method (Cody and Waite's reduction, in turns): u = q / 4 + r with q the
// nearest quarter turn, exactly (Sterbenz), |r| <= 1/8; x = 2 pi r lies in
// [-pi/4, pi/4], where Cephes' sinf / cosf polynomials (Moshier 1984-1992)
// are within about an ulp; the quarter q mod 4 swaps and negates them.
#include <cmath>
#include <numbers>

#include "kernels/simd.h"

namespace raypack {

/// sin and cos of 2 pi u, for any finite u (exact turns give exact 0 and
/// +-1). F is float or a float batch; both compute the same bits.
template <class F>
RAYPACK_INLINE void sin_cos_turns(F u, F& sin_out, F& cos_out) {
    const F q = round_nearest(u * F(4.0f));
    const F x = (u - q * F(0.25f)) * F(2.0f * std::numbers::pi_v<float>);
    const F z = x * x;
    const F s = x + x * z * ((F(-1.9515295891e-4f) * z + F(8.3321608736e-3f)) * z + F(-1.6666654611e-1f));
    const F c = F(1.0f) - F(0.5f) * z + z * z * ((F(2.443315711809948e-5f) * z + F(-1.388731625493765e-3f)) * z +
                                               F(4.166664568298827e-2f));
    // The quarter turn q mod 4, as a float in {0, 1, 2, 3}.
    const F m = q - F(4.0f) * round_down(q * F(0.25f));
    const auto odd = (m == F(1.0f)) || (m == F(3.0f));
    const F sin_x = select(odd, c, s), cos_x = select(odd, s, c);
    sin_out = select(m >= F(2.0f), -sin_x, sin_x);
    cos_out = select((m == F(1.0f)) || (m == F(2.0f)), -cos_x, cos_x);
}

}  // namespace raypack
