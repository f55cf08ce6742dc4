#include "accel/bvh/build_from_scene.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <vector>

#include "accel/bvh/bvh_builders.h"
#include "accel/bvh/spatial_split_builder.h"

namespace raypack {
namespace {

// Widens a box by one float step each way around a point computed in double.
void extend_rounded(Box3f& box, const Vec3d& p) {
    for (int a = 0; a < 3; ++a) {
        const float f = float(p[a]);
        box.lo[a] = std::min(box.lo[a], double(f) > p[a] ? std::nextafter(f, -INFINITY) : f);
        box.hi[a] = std::max(box.hi[a], double(f) < p[a] ? std::nextafter(f, INFINITY) : f);
    }
}

/// Bounds of the parts of triangle v on either side of the plane, each
/// intersected with the reference's current box (the split of Embree's
/// spatial split builder, common/builders/splitter.h): the vertices on each
/// side plus the points where the edges cross the plane.
void split_triangle(const Vec3f (&v)[3], const Box3f& box, int axis, float position, Box3f& left, Box3f& right) {
    Box3f l, r;
    for (int i = 0; i < 3; ++i) {
        const Vec3f& p = v[i];
        const Vec3f& q = v[(i + 1) % 3];
        if (p[axis] <= position) l.extend(p);
        if (p[axis] >= position) r.extend(p);
        if ((p[axis] < position && q[axis] > position) || (p[axis] > position && q[axis] < position)) {
            const Vec3d pd(p), qd(q);
            const double t = (double(position) - pd[axis]) / (qd[axis] - pd[axis]);
            Vec3d x = pd + (qd - pd) * t;
            x[axis] = position;
            extend_rounded(l, x);
            extend_rounded(r, x);
        }
    }
    left = l, right = r;
    left.lo = max(left.lo, box.lo), left.hi = min(left.hi, box.hi);
    right.lo = max(right.lo, box.lo), right.hi = min(right.hi, box.hi);
    left.hi[axis] = std::min(left.hi[axis], position);
    right.lo[axis] = std::max(right.lo[axis], position);
    if (left.empty()) left = Box3f{};
    if (right.empty()) right = Box3f{};
}

/// The parts of a sphere on either side of the plane, within the reference's
/// current box: the side that holds a cap without the centre is narrower
/// than the box (radius sqrt(r^2 - d^2) across the plane, padded for rounding).
void split_sphere(const Vec3f& center, float radius, const Box3f& box, int axis, float position, Box3f& left,
                  Box3f& right) {
    split_box(box, axis, position, left, right);
    const float d = position - center[axis];
    Box3f& cap = d < 0 ? left : right;
    if (cap.empty()) return;
    const float rho = std::sqrt(std::max(0.0f, radius * radius - d * d)) * 1.0001f;
    for (int a = 0; a < 3; ++a) {
        if (a == axis) continue;
        cap.lo[a] = std::max(cap.lo[a], center[a] - rho);
        cap.hi[a] = std::min(cap.hi[a], center[a] + rho);
    }
    if (cap.empty()) cap = Box3f{};
}

}  // namespace

Bvh2 build_scene_bvh2(const Scene& scene, const AccelConfig& config) {
    if (!is_bvh_builder(config.builder)) build_bvh2(config.builder, {}, {});  // throws, naming the builders
    const std::size_t n = scene.primitive_count();
    std::vector<Box3f> boxes(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) boxes[i] = primitive_bounds(scene, std::uint32_t(i));
    });
    BvhBuildConfig bc;
    bc.bins = config.sah_bins;
    bc.max_leaf_size = config.max_leaf_size;
    bc.traversal_cost = config.traversal_cost;
    bc.intersection_cost = config.intersection_cost;
    bc.spatial_alpha = config.spatial_alpha;
    bc.reference_budget = config.reference_budget;
    if (config.builder == "sbvh") {
        // Triangles are cut exactly by the split plane (Stich et al. 2009,
        // sec. 4.3), spheres at the circle the plane cuts; cones clip their boxes.
        bc.split_reference = [&scene](std::uint32_t prim, const Box3f& box, int axis, float position, Box3f& left,
                                      Box3f& right) {
            const PrimRef ref = scene.prims[prim];
            if (ref.kind == PrimKind::Sphere)
                return split_sphere(scene.spheres.center[ref.index], scene.spheres.radius[ref.index], box, axis,
                                    position, left, right);
            if (ref.kind != PrimKind::Triangle) return split_box(box, axis, position, left, right);
            const Vec3f v[3] = {scene.triangles.p0[ref.index], scene.triangles.p1[ref.index],
                                scene.triangles.p2[ref.index]};
            split_triangle(v, box, axis, position, left, right);
        };
    }
    return build_bvh2(config.builder, boxes, bc);
}

}  // namespace raypack
