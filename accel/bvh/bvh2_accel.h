#pragma once
// Scalar traversal of a BVH2, the reference path for every faster BVH.
#include "accel/accel.h"
#include "accel/bvh/bvh2.h"

namespace raypack {

class Bvh2Accel final : public Accel {
public:
    Bvh2Accel(const Scene& scene, const AccelConfig& config);
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    bool supports_packet(int width) const override;
    void intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    bool count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits, TraversalCounts& counts) const override;  // bvh2_counting.cpp
    const Bvh2& bvh() const { return bvh_; }

private:
    /// Every ray of the batch, with the slab test `--slabs` names (chosen
    /// once per batch): out(i, found, hit).
    template <bool AnyHit, class Out>
    void trace(std::span<const Rayf> rays, Out&& out) const;
    template <bool AnyHit>
    void trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const;

    const Scene* scene_;
    KernelChoice kernels_;
    Bvh2 bvh_;
};

}  // namespace raypack
