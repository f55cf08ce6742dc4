#pragma once
// The parametric interval [t0, t1] of rays inside the k-d tree's root box,
// for any lane type: the robust slab test of kernels/aabb.h, but keeping
// the exit too (a k-d tree traversal is driven by both ends of the
// interval). The box is widened by the tree's margin on every side.
#include <limits>

#include "kernels/aabb.h"

namespace raypack {

template <class F>
RAYPACK_INLINE mask_of<F> kd_ray_interval(const mask_of<F>& valid, const Vec3<F>& org, const Vec3<F>& rdir,
                                          const F& tnear, const F& tfar, const Box3f& box, float margin, F& t0,
                                          F& t1) {
    const F huge = F(1) / F(kMinRcpInput), inf(std::numeric_limits<float>::infinity());
    mask_of<F> ok = valid;
    F lo_t = tnear, hi_t = tfar;
    for (int a = 0; a < 3; ++a) {
        const F lo(box.lo[a] - margin), hi(box.hi[a] + margin);
        const F o = org[a], r = rdir[a];
        F ta = (lo - o) * r, tb = (hi - o) * r;
        // A component reciprocal() clamped: the ray is parallel to this slab.
        const auto parallel = vabs(r) >= huge;
        ok = ok & !(parallel & ((o < lo) | (o > hi)));
        ta = select(parallel, -inf, ta);
        tb = select(parallel, inf, tb);
        lo_t = vmax(lo_t, vmin(ta, tb));
        hi_t = vmin(hi_t, vmax(ta, tb));
    }
    t0 = lo_t;
    t1 = hi_t;
    return ok & (lo_t <= hi_t);
}

}  // namespace raypack
