#pragma once
// The traversal variants `--slabs` and `--rcp` (KernelChoice) as the cell
// structures (grid, octree, k-d tree) use them: one plane distance in both
// slab forms, and the approximate reciprocal of single rays.
#include <type_traits>

#include "kernels/aabb.h"
#include "kernels/simd.h"

namespace raypack {

/// Selects a traversal's slab form at compile time; constructors take it as
/// an argument, since their template arguments cannot be named.
template <SlabMethod S>
using SlabTag = std::integral_constant<SlabMethod, S>;

/// Calls body(SlabTag<S>{}) for the S `slabs` names: the caller's loop is
/// compiled once per slab form and chosen once per batch (choosing per ray
/// cost the octree 25%).
template <class Body>
RAYPACK_INLINE void with_slab_form(SlabMethod slabs, Body&& body) {
    if (slabs == SlabMethod::Plain) body(SlabTag<SlabMethod::Plain>{});
    else body(SlabTag<SlabMethod::Robust>{});
}

/// Parameter at which the ray crosses the plane x_axis = p.
/// Robust: (p - org) * rdir, as the robust slab test (Ize, JCGT 2013):
/// exactly 0 for an origin on the plane, whatever rdir.
/// Plain: one fused p * rdir - org * rdir with org * rdir computed once per
/// ray (Embree's form, intersect_box<Plain>): one operation fewer, but an
/// origin on the plane gives the rounding error of org * rdir, which a
/// clamped rdir (+-1e18, a direction component of +-0) makes large.
template <SlabMethod S, class F>
RAYPACK_INLINE F plane_distance(const F& p, const F& org, const F& rdir, const F& org_rdir) {
    if constexpr (S == SlabMethod::Plain) return vfmsub(p, rdir, org_rdir);
    else return (p - org) * rdir;
}

/// reciprocal(dir, RcpMethod::Approx), out of line (see ray_reciprocal).
[[gnu::noinline]] inline Vec3f approx_ray_reciprocal(const Vec3f& dir) { return reciprocal(dir, RcpMethod::Approx); }

/// reciprocal(dir, rcp) for the single-ray walks. The approximate path stays
/// out of line: inlined, its branches made gcc 12 compile the octree walk
/// around it 25% slower even with exact reciprocals.
RAYPACK_INLINE Vec3f ray_reciprocal(const Vec3f& dir, RcpMethod rcp) {
    if (rcp == RcpMethod::Exact) [[likely]]
        return reciprocal(dir);
    return approx_ray_reciprocal(dir);
}

}  // namespace raypack
