#pragma once
// Exact triangle-box overlap by the separating axis theorem (Akenine-Moeller,
// "Fast 3D Triangle-Box Overlap Testing", JGT 2001): a triangle and an
// axis-aligned box are disjoint iff their projections are disjoint on one of
// 13 axes: the 3 box normals, the triangle normal, and the 9 cross products
// of a box normal with a triangle edge. Closed sets: touching at a face, an
// edge or a single corner counts as overlap.
#include <algorithm>
#include <cmath>

#include "kernels/vec3.h"

namespace raypack {

/// True if triangle (a, b, c) meets the closed box center +- half. Degenerate
/// triangles (a segment or a point) are handled: their edge axes are then the
/// separating axes of a segment, and the zero normal separates nothing.
template <class T>
bool triangle_box_overlap(const Vec3<T>& center, const Vec3<T>& half, const Vec3<T>& a, const Vec3<T>& b,
                          const Vec3<T>& c) {
    // Move the box to the origin.
    const Vec3<T> v0 = a - center, v1 = b - center, v2 = c - center;
    // Projections of the triangle onto `axis` against the box's projection radius.
    auto separated = [&](const Vec3<T>& axis) {
        const T p0 = dot(axis, v0), p1 = dot(axis, v1), p2 = dot(axis, v2);
        const T r = half.x * std::fabs(axis.x) + half.y * std::fabs(axis.y) + half.z * std::fabs(axis.z);
        return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
    };
    // 1. Box normals: the triangle's bounding box against the box (cheapest, first).
    for (int k = 0; k < 3; ++k) {
        if (std::min({v0[k], v1[k], v2[k]}) > half[k] || std::max({v0[k], v1[k], v2[k]}) < -half[k]) return false;
    }
    // 2. The nine edge x box-normal axes.
    const Vec3<T> edges[3] = {v1 - v0, v2 - v1, v0 - v2};
    for (const Vec3<T>& e : edges) {
        if (separated(Vec3<T>{T(0), -e.z, e.y})) return false;  // x-axis cross e
        if (separated(Vec3<T>{e.z, T(0), -e.x})) return false;  // y-axis cross e
        if (separated(Vec3<T>{-e.y, e.x, T(0)})) return false;  // z-axis cross e
    }
    // 3. The triangle's plane against the box.
    return !separated(cross(edges[0], edges[1]));
}

}  // namespace raypack
