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

private:
    const Derived& self() const { return static_cast<const Derived&>(*this); }
    template <bool AnyHit>
    bool counting_walk(Rayf& ray, Hitf& hit, Counters& counters) const;
};

}  // namespace raypack
