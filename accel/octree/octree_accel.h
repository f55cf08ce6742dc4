#pragma once
// Adaptive octree traversed by the parametric algorithm of Revelles, Urena &
// Lastra (WSCG 2000); single ray and K-wide packets.
#include <cstdint>

#include "accel/cell_accel.h"
#include "accel/octree/octree.h"

namespace raypack {

/// Per-ray work, gathered by the counting traversal only.
struct OctreeRayCounters {
    std::uint64_t rays = 0;
    std::uint64_t nodes_visited = 0;         ///< nodes entered, inner and leaves (empty ones included)
    std::uint64_t leaves_visited = 0;        ///< non-empty leaves whose primitives were tested
    std::uint64_t empty_leaves_visited = 0;  ///< empty leaves entered
    std::uint64_t prim_tests = 0;            ///< ray-primitive tests run
    void add_to(TraversalCounts& c) const {
        c.nodes += nodes_visited;
        c.leaves += leaves_visited + empty_leaves_visited;
        c.empty_leaves += empty_leaves_visited;
        c.prims += prim_tests;
    }
};

class OctreeAccel final : public CellAccel<OctreeAccel, OctreeRayCounters> {
public:
    OctreeAccel(const Scene& scene, const AccelConfig& config, const OctreeConfig& octree_config = {});

    const Octree& octree() const { return tree_; }
    std::size_t reference_count() const { return tree_.refs.size(); }
    /// References per primitive: how often the average primitive is stored.
    double references_per_primitive() const;
    std::size_t empty_leaves() const { return empty_leaves_; }

private:
    friend class CellAccel<OctreeAccel, OctreeRayCounters>;
    template <bool AnyHit, bool Counting, SlabMethod Slabs>
    bool walk(Rayf& ray, Hitf& hit, OctreeRayCounters* counters) const;
    template <bool AnyHit>
    void trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const;
    bool packets_exact() const { return true; }
    SlabMethod slab_method() const { return kernels_.slabs; }

    const Scene* scene_;
    KernelChoice kernels_;
    Octree tree_;
    std::size_t empty_leaves_ = 0;
    bool packet_groups_;
};

extern template class CellAccel<OctreeAccel, OctreeRayCounters>;  // octree_accel.cpp

}  // namespace raypack
