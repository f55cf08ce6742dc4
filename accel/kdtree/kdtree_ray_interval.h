#pragma once
// The parametric interval [t0, t1] of rays inside the k-d tree's root box,
// for any lane type: the slab test of kernels/aabb.h, but keeping the exit
// too (a k-d tree traversal is driven by both ends of the interval).
// Robust: the box is widened by the tree's margin on every side and a
// parallel axis bounds nothing (as Ize 2013's test, kernels/aabb.h).
// Plain (`--slabs plain`): the exact box, distances p * rdir - org * rdir
// in one fused operation, no parallel-axis case (as intersect_box<Plain>).
#include <limits>

#include "accel/cell_kernel_variants.h"
#include "kernels/aabb.h"

namespace raypack {

template <class F, SlabMethod S = SlabMethod::Robust>
RAYPACK_INLINE mask_of<F> kd_ray_interval(const mask_of<F>& valid, const Vec3<F>& org, const Vec3<F>& rdir,
                                          const F& tnear, const F& tfar, const Box3f& box, float margin, F& t0,
                                          F& t1) {
    const F huge = F(1) / F(kMinRcpInput), inf(std::numeric_limits<float>::infinity());
    mask_of<F> ok = valid;
    F lo_t = tnear, hi_t = tfar;
    for (int a = 0; a < 3; ++a) {
        const F o = org[a], r = rdir[a];
        F ta, tb;
        if constexpr (S == SlabMethod::Plain) {
            const F od = o * r;
            ta = plane_distance<S>(F(box.lo[a]), o, r, od), tb = plane_distance<S>(F(box.hi[a]), o, r, od);
        } else {
            const F lo(box.lo[a] - margin), hi(box.hi[a] + margin);
            ta = (lo - o) * r, tb = (hi - o) * r;
            // A component reciprocal() clamped: the ray is parallel to this slab.
            const auto parallel = vabs(r) >= huge;
            ok = ok & !(parallel & ((o < lo) | (o > hi)));
            ta = select(parallel, -inf, ta);
            tb = select(parallel, inf, tb);
        }
        lo_t = vmax(lo_t, vmin(ta, tb));
        hi_t = vmin(hi_t, vmax(ta, tb));
    }
    t0 = lo_t;
    t1 = hi_t;
    return ok & (lo_t <= hi_t);
}

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
