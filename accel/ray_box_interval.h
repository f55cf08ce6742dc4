#pragma once
// The parametric interval [t0, t1] of rays inside a box, for any lane type:
// the slab test of kernels/aabb.h, but keeping the exit too (the k-d tree's
// walks are driven by both ends of the interval; the octree's groups of
// packets clip their lanes to a leaf with it).
// Robust: the box is widened by `margin` on every side and a parallel axis
// bounds nothing (as Ize 2013's test, kernels/aabb.h).
// Plain (`--slabs plain`): the exact box, distances p * rdir - org * rdir
// in one fused operation, no parallel-axis case (as intersect_box<Plain>).
#include <limits>

#include "accel/cell_kernel_variants.h"
#include "kernels/aabb.h"

namespace raypack {

template <class F, SlabMethod S = SlabMethod::Robust>
RAYPACK_INLINE mask_of<F> ray_box_interval(const mask_of<F>& valid, const Vec3<F>& org, const Vec3<F>& rdir,
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

}  // namespace raypack
