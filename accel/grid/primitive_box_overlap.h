#pragma once
// Does one scene primitive, whatever its kind, meet a box? The grid builder
// asks it for every cell of a primitive's bounding box that the box alone
// cannot decide; like PrimitiveIntersector, it is the one place that looks at
// primitive kinds. Computed in double on closed boxes, so it errs on the side
// of overlap.
#include <cstdint>

#include "accel/grid/triangle_box_overlap.h"
#include "scene/scene.h"

namespace raypack {

struct PrimitiveBoxOverlap {
    const Scene* scene;
    /// If set, the callers' primitive numbers index this table of the
    /// scene's (a sub-grid built over some of the primitives).
    const std::uint32_t* ids = nullptr;

    /// True if the primitive may meet the closed box [lo, hi]: triangles by
    /// the separating axis test, spheres by the distance from the centre to
    /// the box (Arvo, "A Simple Method for Box-Sphere Intersection Testing",
    /// Graphics Gems 1990), cones by their bounding box only.
    bool overlaps(std::uint32_t prim, const Vec3d& lo, const Vec3d& hi) const {
        const PrimRef ref = scene->prims[ids ? ids[prim] : prim];
        const std::uint32_t i = ref.index;
        switch (ref.kind) {
            case PrimKind::Triangle: {
                const Vec3d center = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
                return triangle_box_overlap(center, half, Vec3d(scene->triangles.p0[i]),
                                            Vec3d(scene->triangles.p1[i]), Vec3d(scene->triangles.p2[i]));
            }
            case PrimKind::Sphere: {
                const Vec3d c(scene->spheres.center[i]);
                const double r = scene->spheres.radius[i];
                double d2 = 0;
                for (int a = 0; a < 3; ++a) {
                    const double d = c[a] < lo[a] ? lo[a] - c[a] : c[a] > hi[a] ? c[a] - hi[a] : 0.0;
                    d2 += d * d;
                }
                return d2 <= r * r;
            }
            case PrimKind::Cone:
            case PrimKind::HeightField:
            case PrimKind::Instance:
                return true;  // the caller has already intersected the bounding boxes
        }
        return true;
    }
};

}  // namespace raypack
