#pragma once
// The k-d tree's ray intervals: ray_box_interval (accel/ray_box_interval.h)
// for its root box and leaves, and the widened tfar of its double-precision
// tie rule.
#include <limits>

#include "accel/ray_box_interval.h"
#include "kernels/simd.h"

namespace raypack {

/// `--precision double` makes the order of the leaves matter on ties: a
/// primitive whose double t rounds to the closest float t so far may lie just
/// beyond it and be rejected if tested second, accepted if tested first.
/// After a hit, the traversals therefore test against tfar widened by this
/// (a few ulps), drop what lies beyond the closest hit and keep the lowest
/// primitive on equal t: the answer is then the same in every order, as
/// packets (which order nodes by one lane) need.
template <class F>
RAYPACK_INLINE F kd_tie_tfar(const F& tfar) {
    return tfar + vabs(tfar) * F(0x1p-22f) + F(std::numeric_limits<float>::denorm_min());
}

}  // namespace raypack
