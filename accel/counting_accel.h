#pragma once
// A structure seen through its counting walk: every query of the interface
// goes through the wrapped structure's Accel::count_traversal (its own
// single-ray walk with counters: the same answers, ray for ray) and adds
// Havran's measures up, so that a whole render reports what each structure
// cost per ray over all its rays, eye, shadow and secondary together, as
// Havran and Sixta measured the SPD scenes (1999). Slower; never timed.
#include <atomic>
#include <cstdint>
#include <span>

#include "accel/accel.h"

namespace raypack {

class CountingAccel final : public Accel {
public:
    /// Throws std::invalid_argument if `inner` cannot count (Embree, instances).
    explicit CountingAccel(const Accel& inner);
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    const AccelStats& stats() const override { return inner_.stats(); }
    /// Any width: the counting walk takes rays one at a time whatever the caller's packets.
    bool supports_packet(int) const override { return true; }
    void intersect_packets(int, std::span<const Rayf> rays, std::span<Hitf> hits) const override {
        intersect(rays, hits);
    }
    void occluded_packets(int, std::span<const Rayf> rays, std::span<std::uint8_t> occluded_out) const override {
        occluded(rays, occluded_out);
    }

    /// The sums so far, and the rays they are over.
    TraversalCounts totals() const;
    std::uint64_t rays() const { return rays_.load(); }

private:
    void add(const TraversalCounts& c, std::size_t rays) const;

    const Accel& inner_;
    mutable std::atomic<std::uint64_t> nodes_{0}, prims_{0}, leaves_{0}, empty_leaves_{0}, rays_{0};
};

}  // namespace raypack
