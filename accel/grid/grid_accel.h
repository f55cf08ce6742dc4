#pragma once
// Uniform grid traversed by a 3D-DDA: single rays (dda.h) and K-wide
// packets with every lane stepping its own walk (dda_packet.h).
#include <array>
#include <cstdint>

#include "accel/cell_accel.h"
#include "accel/grid/grid.h"

namespace raypack {

/// Per-ray work, gathered by the counting traversal only.
struct GridRayCounters {
    std::uint64_t rays = 0;
    std::uint64_t cells_visited = 0;        ///< cells the DDA yielded, empty ones included
    std::uint64_t empty_cells_visited = 0;  ///< of which empty
    std::uint64_t prim_tests = 0;           ///< ray-primitive tests run
    std::uint64_t mailbox_skips = 0;        ///< repeated tests the mailbox avoided
    /// Havran's measures: a grid's traversal steps are its cells.
    void add_to(TraversalCounts& c) const {
        c.nodes += cells_visited;
        c.leaves += cells_visited;
        c.empty_leaves += empty_cells_visited;
        c.prims += prim_tests;
    }
};

/// Packets (grid_packet.h): coherent packets walk slice by slice (Wald et
/// al. 2006), the others step each lane's own DDA; the latter have no
/// mailbox and answer as the single-ray walk with GridConfig::mailbox off,
/// bit for bit.
class GridAccel final : public CellAccel<GridAccel, GridRayCounters> {
public:
    GridAccel(const Scene& scene, const AccelConfig& config, const GridConfig& grid_config = {});

    const Grid& grid() const { return grid_; }
    std::array<int, 3> resolution() const { return grid_.geometry.res; }
    std::size_t cell_count() const { return grid_.geometry.cells(); }
    std::size_t reference_count() const { return grid_.refs.size(); }
    /// Cells per primitive actually used (below GridConfig::lambda only if
    /// the reference cap forced coarser cells).
    float lambda() const { return grid_.lambda; }
    /// References per primitive: how often the average primitive is stored.
    double references_per_primitive() const;
    double empty_cell_fraction() const;
    std::size_t empty_cells() const { return empty_cells_; }

private:
    friend class CellAccel<GridAccel, GridRayCounters>;
    template <bool AnyHit>
    void trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const;
    template <bool AnyHit, bool Counting, bool Mailbox, SlabMethod Slabs>
    bool trace(Rayf& ray, Hitf& hit, GridRayCounters* counters) const;
    /// One ray: trace() with or without the mailbox, chosen per ray as before the variants.
    template <bool AnyHit, bool Counting, SlabMethod Slabs>
    bool walk(Rayf& ray, Hitf& hit, GridRayCounters* counters) const {
        return mailbox_ ? trace<AnyHit, Counting, true, Slabs>(ray, hit, counters)
                        : trace<AnyHit, Counting, false, Slabs>(ray, hit, counters);
    }
    bool packets_exact() const;
    SlabMethod slab_method() const { return kernels_.slabs; }

    const Scene* scene_;
    KernelChoice kernels_;
    Grid grid_;
    std::size_t empty_cells_ = 0;
    bool mailbox_ = true;
    bool coherent_packets_ = true;
};

extern template class CellAccel<GridAccel, GridRayCounters>;  // grid_accel.cpp

}  // namespace raypack
