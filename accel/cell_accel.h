#pragma once
// What the cell structures (uniform grid, k-d tree, octree) answer the same
// way around their own walks: single rays with the slab form chosen once per
// batch, the counting walk and Havran's measures, packets of every compiled
// width (accel/packet_widths.h) and occlusion through them. One base
// (CRTP), so that the three structures differ only in their walks. The
// members are defined in accel/cell_accel_impl.h and instantiated in each
// structure's .cpp, next to its walk.
#include <cstdint>
#include <span>

#include "accel/accel.h"
#include "accel/cell_kernel_variants.h"
#include "accel/prims/triangle_edges.h"

namespace raypack {

/// Derived provides, to this class (befriend it):
///   template <bool AnyHit, bool Counting, SlabMethod Slabs>
///   bool walk(Rayf& ray, Hitf& hit, Counters* counters) const;  // one ray
///   template <bool AnyHit>
///   void trace_packets(int width, std::span<const Rayf>, std::span<Hitf>) const;
///   bool packets_exact() const;  // false: packets run as single rays
///   SlabMethod slab_method() const;
template <class Derived, class Counters>
class CellAccel : public Accel {
public:
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;

    /// The same queries, adding each ray's work to `counters` (slower; tests and analysis).
    Hitf intersect_counting(const Rayf& ray, Counters& counters) const;
    bool occluded_counting(const Rayf& ray, Counters& counters) const;
    bool count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                         TraversalCounts& counts) const override;

    bool supports_packet(int width) const override;
    void intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;

    /// Memory of the triangle records (make_triangle_edges), part of stats().bytes.
    std::size_t triangle_edge_bytes() const { return triangle_edges_.bytes(); }

protected:
    /// Moeller's records of the scene's triangles for the leaves' tests
    /// (accel/prims/triangle_edges.h), when `kernels` test triangles by
    /// Moeller-Trumbore in float (the default): made by each structure's
    /// constructor, counted in its build time and memory. Other kernels
    /// read the vertices.
    void make_triangle_edges(const Scene& scene, const KernelChoice& kernels) {
        if (kernels.triangle == TriangleMethod::Moeller && kernels.precision == Precision::Float)
            triangle_edges_ = TriangleEdgeTable(scene);
    }
    const TriangleEdgeRecord* triangle_edges() const { return triangle_edges_.data(); }

private:
    TriangleEdgeTable triangle_edges_;

    const Derived& self() const { return static_cast<const Derived&>(*this); }
    template <bool AnyHit>
    bool counting_walk(Rayf& ray, Hitf& hit, Counters& counters) const;
};

}  // namespace raypack
