#pragma once
// Tight bounds of one scene primitive inside a voxel, for the k-d tree's
// perfect splits (Havran, "Heuristic Ray Shooting Algorithms", PhD thesis
// 2000, sec. 4.5; Wald & Havran 2006, sec. 4.3). Like PrimitiveIntersector,
// the one place of the k-d tree that looks at primitive kinds.
#include <cmath>
#include <cstdint>
#include <limits>

#include "scene/scene.h"

namespace raypack {

struct PrimitiveClipper {
    const Scene* scene;
    bool perfect = true;  ///< clip triangles; false clips boxes only

    /// Bounds of prim within the closed box `voxel`, rounded outwards to
    /// float and kept inside the voxel; false if they do not meet.
    bool clip(std::uint32_t prim, const Box3f& voxel, Box3f& out) const {
        const PrimRef ref = scene->prims[prim];
        if (perfect && ref.kind == PrimKind::Triangle) {
            const std::uint32_t i = ref.index;
            return clip_triangle(Vec3d(scene->triangles.p0[i]), Vec3d(scene->triangles.p1[i]),
                                 Vec3d(scene->triangles.p2[i]), voxel, out);
        }
        // Spheres and cones: their box clipped to the voxel.
        const Box3f b = primitive_bounds(*scene, prim);
        out.lo = max(b.lo, voxel.lo);
        out.hi = min(b.hi, voxel.hi);
        return !out.empty();
    }

    /// Sutherland-Hodgman clipping of the triangle by the voxel's six planes
    /// in double, keeping points on the planes (closed voxel).
    static bool clip_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Box3f& voxel, Box3f& out) {
        Vec3d poly[2][9];
        int n = 3;
        poly[0][0] = a, poly[0][1] = b, poly[0][2] = c;
        int cur = 0;
        for (int axis = 0; axis < 3 && n > 0; ++axis) {
            for (int side = 0; side < 2 && n > 0; ++side) {
                const double plane = side == 0 ? double(voxel.lo[axis]) : double(voxel.hi[axis]);
                auto inside = [&](const Vec3d& p) { return side == 0 ? p[axis] >= plane : p[axis] <= plane; };
                const Vec3d* in = poly[cur];
                Vec3d* res = poly[1 - cur];
                int m = 0;
                for (int k = 0; k < n; ++k) {
                    const Vec3d& p = in[k];
                    const Vec3d& q = in[(k + 1) % n];
                    const bool pin = inside(p), qin = inside(q);
                    if (pin) res[m++] = p;
                    if (pin != qin && m < 9) {
                        const double t = (plane - p[axis]) / (q[axis] - p[axis]);
                        Vec3d x = p + (q - p) * t;
                        x[axis] = plane;  // exactly on the plane
                        res[m++] = x;
                    }
                }
                n = m;
                cur = 1 - cur;
            }
        }
        if (n == 0) return false;
        Vec3d lo = poly[cur][0], hi = poly[cur][0];
        for (int k = 1; k < n; ++k) {
            lo = min(lo, poly[cur][k]);
            hi = max(hi, poly[cur][k]);
        }
        for (int axis = 0; axis < 3; ++axis) {
            out.lo[axis] = std::max(round_down(lo[axis]), voxel.lo[axis]);
            out.hi[axis] = std::min(round_up(hi[axis]), voxel.hi[axis]);
        }
        return !out.empty();
    }

private:
    static float round_down(double x) {
        float f = float(x);
        return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
    }
    static float round_up(double x) {
        float f = float(x);
        return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
    }
};

}  // namespace raypack
