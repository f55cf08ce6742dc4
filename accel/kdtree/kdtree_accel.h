#pragma once
// SAH k-d tree (Wald & Havran 2006 build, pbrt's 8-byte nodes), traversed
// front to back with a stack (Havran's TA_B, pbrt's KdTreeAggregate), one
// ray at a time or in packets of K.
#include <cstdint>

#include "accel/cell_accel.h"
#include "accel/kdtree/kdtree.h"

namespace raypack {

/// Per-ray work, gathered by the counting traversal only.
struct KdRayCounters {
    std::uint64_t rays = 0;
    std::uint64_t nodes_visited = 0;         ///< inner nodes and leaves
    std::uint64_t leaves_visited = 0;        ///< empty ones included
    std::uint64_t empty_leaves_visited = 0;  ///< of which empty
    std::uint64_t prim_tests = 0;            ///< ray-primitive tests run
    void add_to(TraversalCounts& c) const {
        c.nodes += nodes_visited;
        c.leaves += leaves_visited;
        c.empty_leaves += empty_leaves_visited;
        c.prims += prim_tests;
    }
};

class KdTreeAccel final : public CellAccel<KdTreeAccel, KdRayCounters> {
public:
    KdTreeAccel(const Scene& scene, const AccelConfig& config, const KdTreeConfig& kd_config = {});

    const KdTree& tree() const { return tree_; }
    /// References per primitive: how often the average primitive is stored.
    double references_per_primitive() const;
    std::size_t empty_leaves() const { return tree_.empty_leaves; }

private:
    friend class CellAccel<KdTreeAccel, KdRayCounters>;
    template <bool AnyHit, bool Counting, SlabMethod Slabs>
    bool walk(Rayf& ray, Hitf& hit, KdRayCounters* counters) const;
    template <bool AnyHit>
    void trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const;
    bool packets_exact() const { return true; }
    SlabMethod slab_method() const { return kernels_.slabs; }

    const Scene* scene_;
    KernelChoice kernels_;
    bool packet_groups_;
    KdTree tree_;
};

extern template class CellAccel<KdTreeAccel, KdRayCounters>;  // kdtree_accel.cpp

}  // namespace raypack
