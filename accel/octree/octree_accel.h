#pragma once
// Adaptive octree traversed by the parametric algorithm of Revelles, Urena &
// Lastra (WSCG 2000); single ray and K-wide packets.
#include <cstdint>

#include "accel/accel.h"
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

class OctreeAccel final : public Accel {
public:
    OctreeAccel(const Scene& scene, const AccelConfig& config, const OctreeConfig& octree_config = {});
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    const AccelStats& stats() const override { return stats_; }

    bool supports_packet(int width) const override;
    void intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;

    /// The same queries, adding each ray's work to `counters` (slower; tests and analysis).
    Hitf intersect_counting(const Rayf& ray, OctreeRayCounters& counters) const;
    bool occluded_counting(const Rayf& ray, OctreeRayCounters& counters) const;
    bool count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                         TraversalCounts& counts) const override;

    const Octree& octree() const { return tree_; }
    std::size_t reference_count() const { return tree_.refs.size(); }
    /// References per primitive: how often the average primitive is stored.
    double references_per_primitive() const;
    std::size_t empty_leaves() const { return empty_leaves_; }

private:
    template <bool AnyHit, bool Counting, SlabMethod Slabs>
    bool trace(Rayf& ray, Hitf& hit, OctreeRayCounters* counters) const;
    /// The counting walk picks the slab form per ray (it is never timed).
    template <bool AnyHit, bool Counting>
    bool trace(Rayf& ray, Hitf& hit, OctreeRayCounters* counters) const {
        return kernels_.slabs == SlabMethod::Plain ? trace<AnyHit, Counting, SlabMethod::Plain>(ray, hit, counters)
                                                   : trace<AnyHit, Counting, SlabMethod::Robust>(ray, hit, counters);
    }
    template <bool AnyHit>
    void trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const;

    const Scene* scene_;
    KernelChoice kernels_;
    Octree tree_;
    std::size_t empty_leaves_ = 0;
    AccelStats stats_;
};

}  // namespace raypack
