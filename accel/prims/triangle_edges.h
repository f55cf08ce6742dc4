#pragma once
// Moeller-Trumbore's per-triangle part (p0, p0 - p1, p2 - p0 and their cross
// product) of every triangle of a scene, computed once when a structure is
// built, for the octree and the grids, whose leaves hold primitive numbers:
// their tests read the scene's vertices and formed the edges and the normal
// at every ray-triangle test. The BVHs' leaf blocks hold the same values
// (TriangleLayout::Edges); the k-d tree measured no faster with them
// (docs/structures.md) and keeps the vertices.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/ray_packet.h"
#include "kernels/triangle.h"
#include "kernels/vec3.h"
#include "scene/scene.h"

namespace raypack {

/// One triangle's Moeller quantities, as triangle_detail::moeller_edges
/// computes them from its vertices (48 bytes).
struct TriangleEdgeRecord {
    Vec3f p0, e1n, e2, ng;
};

/// Triangle i's record from its vertices.
inline TriangleEdgeRecord triangle_edge_record(const TriangleSoA& tr, std::size_t i) {
    const auto e = triangle_detail::moeller_edges(tr.p0[i], tr.p1[i], tr.p2[i]);
    return {tr.p0[i], e.e1n, e.e2, e.ng};
}

/// The records of every triangle of a scene, by triangle index
/// (Scene::triangles), or none.
class TriangleEdgeTable {
public:
    TriangleEdgeTable() = default;
    /// Every triangle's record (in parallel for large scenes).
    explicit TriangleEdgeTable(const Scene& scene);

    /// The records, or null if there are none (no triangles, or a table
    /// made empty): the tests then read the vertices.
    const TriangleEdgeRecord* data() const { return records_.empty() ? nullptr : records_.data(); }
    std::size_t bytes() const { return records_.size() * sizeof(TriangleEdgeRecord); }

private:
    std::vector<TriangleEdgeRecord> records_;
};

/// The active lanes of a packet (or one ray, F = float) against a triangle
/// by its record: the same values and hits, bit for bit, as
/// intersect_triangle_moeller on its vertices. t, u, v are defined on the
/// lanes hit.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_record(const TriangleEdgeRecord& r, mask_of<F> valid,
                                                    const Vec3<F>& org, const Vec3<F>& dir, const F& tnear,
                                                    const F& tfar, F& t, F& u, F& v) {
    const Vec3<F> p0{F(r.p0.x), F(r.p0.y), F(r.p0.z)}, e1n{F(r.e1n.x), F(r.e1n.y), F(r.e1n.z)},
        e2{F(r.e2.x), F(r.e2.y), F(r.e2.z)}, ng{F(r.ng.x), F(r.ng.y), F(r.ng.z)};
    return intersect_triangle_moeller_edges<F>(valid, org, dir, tnear, tfar, p0, e1n, e2, ng, t, u, v);
}

}  // namespace raypack
