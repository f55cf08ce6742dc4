#pragma once
// SAH k-d tree (Wald & Havran 2006 build, pbrt's 8-byte nodes), traversed
// front to back with a stack (Havran's TA_B, pbrt's KdTreeAggregate), one
// ray at a time or in packets of K.
#include <cstdint>

#include "accel/accel.h"
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

class KdTreeAccel final : public Accel {
public:
    KdTreeAccel(const Scene& scene, const AccelConfig& config, const KdTreeConfig& kd_config = {});
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    const AccelStats& stats() const override { return stats_; }
    bool supports_packet(int width) const override;
    void intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;

    /// The same queries, adding each ray's work to `counters` (slower; tests and analysis).
    Hitf intersect_counting(const Rayf& ray, KdRayCounters& counters) const;
    bool occluded_counting(const Rayf& ray, KdRayCounters& counters) const;
    bool count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                         TraversalCounts& counts) const override;

    const KdTree& tree() const { return tree_; }
    /// References per primitive: how often the average primitive is stored.
    double references_per_primitive() const;
    std::size_t empty_leaves() const { return tree_.empty_leaves; }

private:
    template <bool AnyHit, bool Counting, SlabMethod Slabs>
    bool trace(Rayf& ray, Hitf& hit, KdRayCounters* counters) const;
    /// The counting walk picks the slab form per ray (it is never timed).
    template <bool AnyHit, bool Counting>
    bool trace(Rayf& ray, Hitf& hit, KdRayCounters* counters) const {
        return kernels_.slabs == SlabMethod::Plain ? trace<AnyHit, Counting, SlabMethod::Plain>(ray, hit, counters)
                                                   : trace<AnyHit, Counting, SlabMethod::Robust>(ray, hit, counters);
    }
    template <bool AnyHit>
    void trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const;

    const Scene* scene_;
    KernelChoice kernels_;
    KdTree tree_;
    AccelStats stats_;
};

}  // namespace raypack
