#include "accel/bvh/build_from_scene.h"

#include <tbb/parallel_for.h>

#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "accel/bvh/bvh_builders.h"
#include "accel/bvh/spatial_split_builder.h"

namespace raypack {
namespace {

// The float just below / above a finite float (std::nextafter is an
// out-of-line libm call and was a fifth of the SBVH build).
float next_down(float f) {
    if (f == 0.0f) return -std::numeric_limits<float>::denorm_min();
    const auto bits = std::bit_cast<std::uint32_t>(f);
    return std::bit_cast<float>(f > 0 ? bits - 1 : bits + 1);
}
float next_up(float f) { return -next_down(-f); }

/// Bounds of the parts of triangle v on either side of the plane, each
/// intersected with the reference's current box (the split of Embree's
/// spatial split builder, common/builders/splitter.h): the vertices on each
/// side plus the points where the edges cross the plane, computed in double
/// and rounded outwards.
void split_triangle(const Vec3f (&v)[3], const Box3f& box, int axis, float position, Box3f& left, Box3f& right) {
    float p[3][3];
    for (int i = 0; i < 3; ++i) p[i][0] = v[i].x, p[i][1] = v[i].y, p[i][2] = v[i].z;
    constexpr float inf = std::numeric_limits<float>::infinity();
    float l_lo[3] = {inf, inf, inf}, l_hi[3] = {-inf, -inf, -inf};
    float r_lo[3] = {inf, inf, inf}, r_hi[3] = {-inf, -inf, -inf};
    auto extend = [](float* lo, float* hi, int a, float x_lo, float x_hi) {
        lo[a] = std::min(lo[a], x_lo);
        hi[a] = std::max(hi[a], x_hi);
    };
    for (int i = 0; i < 3; ++i) {
        const float* a = p[i];
        const float* b = p[(i + 1) % 3];
        for (int k = 0; k < 3; ++k) {
            if (a[axis] <= position) extend(l_lo, l_hi, k, a[k], a[k]);
            if (a[axis] >= position) extend(r_lo, r_hi, k, a[k], a[k]);
        }
        if ((a[axis] < position && b[axis] > position) || (a[axis] > position && b[axis] < position)) {
            const double t = (double(position) - double(a[axis])) / (double(b[axis]) - double(a[axis]));
            for (int k = 0; k < 3; ++k) {
                float lo = position, hi = position;
                if (k != axis) {
                    const double x = double(a[k]) + (double(b[k]) - double(a[k])) * t;
                    const float f = float(x);
                    lo = double(f) > x ? next_down(f) : f;
                    hi = double(f) < x ? next_up(f) : f;
                }
                extend(l_lo, l_hi, k, lo, hi);
                extend(r_lo, r_hi, k, lo, hi);
            }
        }
    }
    for (int k = 0; k < 3; ++k) {
        left.lo[k] = std::max(l_lo[k], box.lo[k]), left.hi[k] = std::min(l_hi[k], box.hi[k]);
        right.lo[k] = std::max(r_lo[k], box.lo[k]), right.hi[k] = std::min(r_hi[k], box.hi[k]);
    }
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

// The surface at axial fraction s lies in the disc of centre
// c(s) = base + s (apex - base) and radius r(s), linear in s, whose extent along axis a is c_a(s) +- r(s) e_a (e_a = sqrt(1 - w_a^2),
// w the unit axis). A side holds the discs whose extent reaches across the
// plane, an interval of s; the union of their boxes is the box of the
// interval's two end discs (every bound is linear in s). Computed in double
// and padded as primitive_bounds pads the whole cone's box.
void split_cone(const Vec3f& base, float base_radius, const Vec3f& apex, float apex_radius, const Box3f& box,
                int axis, float position, Box3f& left, Box3f& right) {
    split_box(box, axis, position, left, right);
    double d[3], e[3];
    for (int a = 0; a < 3; ++a) d[a] = double(apex[a]) - double(base[a]);
    const double len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (!(len2 > 0) || !std::isfinite(len2)) return;
    for (int a = 0; a < 3; ++a) e[a] = std::sqrt(std::max(0.0, 1.0 - d[a] * d[a] / len2)) * 1.0001;
    const double rb = base_radius, dr = double(apex_radius) - double(base_radius);
    // lo(s) = base_ax + s d_ax - r(s) e_ax, hi(s) = base_ax + s d_ax + r(s) e_ax.
    auto reach = [&](double sign, double& at0, double& slope) {
        at0 = double(base[axis]) + sign * rb * e[axis];
        slope = d[axis] + sign * dr * e[axis];
    };
    // Interval of s in [0, 1] where at0 + slope s <= position (below) or >= it.
    auto interval = [&](double at0, double slope, bool below, double& s0, double& s1) {
        s0 = 0, s1 = 1;
        const double x = double(position) - at0;  // at0 + slope s <= position  <=>  slope s <= x
        if (slope == 0) {
            if (below ? 0 > x : 0 < x) s0 = 1, s1 = 0;
            return;
        }
        const double s = x / slope;
        if ((slope > 0) == below) s1 = std::min(1.0, s);
        else s0 = std::max(0.0, s);
    };
    auto discs_box = [&](double s0, double s1, Box3f& part) {
        if (part.empty()) return;
        if (!(s0 <= s1)) {
            part = Box3f{};
            return;
        }
        s0 = std::max(0.0, s0 - 1e-7), s1 = std::min(1.0, s1 + 1e-7);  // past the rounding of x / slope
        Box3f b;
        for (const double s : {s0, s1}) {
            const double r = rb + s * dr;
            for (int a = 0; a < 3; ++a) {
                const double c = double(base[a]) + s * d[a];
                const double lo = c - r * e[a], hi = c + r * e[a];
                float flo = float(lo), fhi = float(hi);
                if (double(flo) > lo) flo = next_down(flo);
                if (double(fhi) < hi) fhi = next_up(fhi);
                b.lo[a] = std::min(b.lo[a], flo);
                b.hi[a] = std::max(b.hi[a], fhi);
            }
        }
        for (int a = 0; a < 3; ++a) {
            part.lo[a] = std::max(part.lo[a], b.lo[a]);
            part.hi[a] = std::min(part.hi[a], b.hi[a]);
        }
        if (part.empty()) part = Box3f{};
    };
    double at0, slope, s0, s1;
    reach(-1.0, at0, slope);  // a disc reaches left of the plane when its low end does
    interval(at0, slope, true, s0, s1);
    discs_box(s0, s1, left);
    reach(+1.0, at0, slope);
    interval(at0, slope, false, s0, s1);
    discs_box(s0, s1, right);
}

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
        // sec. 4.3), spheres at the circle the plane cuts, cones at the discs that reach
        // across the plane.
        bc.split_reference = [&scene](std::uint32_t prim, const Box3f& box, int axis, float position, Box3f& left,
                                      Box3f& right) {
            const PrimRef ref = scene.prims[prim];
            if (ref.kind == PrimKind::Sphere)
                return split_sphere(scene.spheres.center[ref.index], scene.spheres.radius[ref.index], box, axis,
                                    position, left, right);
            if (ref.kind == PrimKind::Cone)
                return split_cone(scene.cones.base[ref.index], scene.cones.base_radius[ref.index],
                                  scene.cones.apex[ref.index], scene.cones.apex_radius[ref.index], box, axis,
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
