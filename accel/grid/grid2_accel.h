#pragma once
// Two-level grid (`--accel grid2`, two_level_grid.h): single rays walk the
// top grid's cells with a 3D-DDA and, in each non-empty cell, that cell's
// own grid over the same stretch of the ray; coherent packets walk both
// levels slice by slice (coherent_grid.h), in groups of 128 rays
// (coherent_grid_group.h).
#include <cstdint>

#include "accel/cell_accel.h"
#include "accel/grid/grid_accel.h"
#include "accel/grid/two_level_grid.h"
#include "accel/packet_intersector.h"
#include "kernels/ray_packet.h"

namespace raypack {

namespace coherent_grid {
template <int K, int G>
struct GroupLanes;
}  // namespace coherent_grid

class Grid2Accel final : public CellAccel<Grid2Accel, GridRayCounters> {
public:
    Grid2Accel(const Scene& scene, const AccelConfig& config, const TwoLevelGridConfig& grid_config = {});
    const TwoLevelGrid& grid() const { return grid_; }

private:
    friend class CellAccel<Grid2Accel, GridRayCounters>;
    template <bool AnyHit>
    void trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const;
    /// The lanes `active` of a packet from `entry` (inside the top grid's box).
    template <int K, bool AnyHit, SlabMethod Slabs>
    void trace_packet(const PacketRecordIntersector<vfloat<K>>& isect, RayPacket<K>& ray, HitPacket<K>& hit,
                      vmask<K> active, vfloat<K> entry, vmask<K>& occluded) const;
    /// Top cell c's grid against the lanes `active`, which all travel one
    /// way along axis k; true once none is left.
    template <int K, bool AnyHit, SlabMethod Slabs>
    bool visit_top_cell(const PacketRecordIntersector<vfloat<K>>& isect, int k, std::uint32_t c, RayPacket<K>& ray,
                        HitPacket<K>& hit, vmask<K>& active, const vfloat<K>& entry, vmask<K>& occluded) const;
    /// visit_top_cell for the packets `here` of a group walking the top grid:
    /// together through c's grid when they share axis k there; clears in
    /// `walking` the packets left without lanes and returns true once none is.
    template <int K, int G, bool AnyHit, SlabMethod Slabs>
    bool visit_top_cell_group(const PacketRecordIntersector<vfloat<K>>& isect, int k, std::uint32_t c,
                              std::uint32_t here, std::uint32_t& walking, coherent_grid::GroupLanes<K, G>& lanes) const;
    /// The lanes `active`, one ray at a time, from `entry` up to their closest hits so far.
    template <int K, bool AnyHit, SlabMethod Slabs>
    void finish_alone(RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> active, const vfloat<K>& entry,
                      vmask<K>& occluded) const;
    template <bool AnyHit, bool Counting, SlabMethod Slabs>
    bool walk(Rayf& ray, Hitf& hit, GridRayCounters* counters) const;
    bool packets_exact() const { return packets_exact_; }
    SlabMethod slab_method() const { return kernels_.slabs; }

    const Scene* scene_;
    KernelChoice kernels_;
    TwoLevelGrid grid_;
    bool packets_exact_ = true;  ///< every grid's counters are exact in floats (grid_packet.h)
};

extern template class CellAccel<Grid2Accel, GridRayCounters>;  // grid2_accel.cpp

}  // namespace raypack
