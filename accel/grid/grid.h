#pragma once
// A uniform grid: the scene box cut into res.x * res.y * res.z equal cells,
// each cell a range of one array of primitive references (the compact layout
// of Lagae & Dutre, "Compact, Fast and Robust Grids for Ray Tracing", EGSR
// 2008: cell c holds refs[cell_begin[c] .. cell_begin[c + 1]]).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/aabb.h"

namespace raypack {

struct GridConfig {
    /// Cells per primitive, the density lambda of the usual heuristic: about
    /// lambda * N near-cubic cells (Cleary & Wyvill, "Analysis of an
    /// algorithm for fast ray tracing using uniform space subdivision", The
    /// Visual Computer 1988; Ize, Shirley & Parker, "Grid Creation Strategies
    /// for Efficient Ray Tracing", RT 2007: O(N) cells is optimal, with a
    /// constant that depends on the scene and on the cost of a cell step
    /// against a primitive test). 24 from raypack's own sweep over the shared
    /// scenes (lambda 4 to 32, camera rays, one ray at a time): the geometric
    /// mean of the speed relative to bvh2 is flat from 16 to 32; compact
    /// meshes (mount, teapot, bunny) prefer 8-12, dense clusters in a large
    /// box (balls, tree) want as many cells as memory allows.
    float lambda = 24.0f;
    /// Upper bounds that keep absurd inputs from exhausting memory: the cell
    /// count (64M cells = 256 MiB of ranges), and the reference count (the
    /// resolution is halved per axis until the references fit).
    std::size_t max_cells = std::size_t(1) << 26;
    std::size_t max_references = std::size_t(1) << 28;
    /// Place triangles by exact triangle-box overlap and spheres by their
    /// distance to the cell; false places every primitive by its box only.
    bool exact_overlap = true;
    /// Skip primitives a ray has already tested in an earlier cell, with a
    /// small hashed mailbox per ray (Amanatides & Woo 1987 mailboxing; the
    /// per-ray hashed form of Wald, "Realtime Ray Tracing and Interactive
    /// Global Illumination", PhD thesis 2004, and Havran's survey).
    bool mailbox = true;
    /// Packets whose rays share a major direction walk slice by slice
    /// (coherent grid traversal, coherent_grid.h); false: every packet steps
    /// each lane's own DDA (dda_packet.h), for comparison and tests.
    bool coherent_packets = true;
    /// A few primitives far larger than the rest (a ground polygon under a
    /// small object: SPD balls, rings, tree) are tested by every ray instead
    /// of being placed in cells, so that the grid's box, and with it the
    /// cells, fit the rest (accel/outside_prims.h).
    bool large_primitives_outside = true;
    /// Cells are widened by at least this much when primitives are placed
    /// (grid_build.h); a sub-grid of a two-level grid takes its parent's.
    float min_placement_margin = 0.0f;
};

/// What the 3D-DDA needs: the grid's box, resolution and cell size.
struct GridGeometry {
    Box3f bounds;
    std::array<int, 3> res{0, 0, 0};
    Vec3f cell_size;
    Vec3f inv_cell_size;  ///< res / extent, maps a coordinate to a cell

    std::size_t cells() const { return std::size_t(res[0]) * std::size_t(res[1]) * std::size_t(res[2]); }
    std::uint32_t cell_index(int x, int y, int z) const {
        return std::uint32_t(x) + std::uint32_t(res[0]) * (std::uint32_t(y) + std::uint32_t(res[1]) * std::uint32_t(z));
    }
    /// Coordinate of the plane between cells i - 1 and i along `axis`.
    float plane(int axis, int i) const { return bounds.lo[axis] + float(i) * cell_size[axis]; }
};

/// Which blocks of 2^shift x 2^shift x 2^shift cells hold any reference
/// (macrocells, Parker et al., "Interactive Ray Tracing for Isosurface
/// Rendering", 1998): the coherent packet walk skips empty blocks whole.
struct MacroCells {
    int shift = 2;
    std::array<int, 3> res{0, 0, 0};
    std::vector<std::uint8_t> full;  ///< 1 if some cell of the block has references

    bool any(int x, int y, int z) const {
        return full[std::size_t(x) + std::size_t(res[0]) * (std::size_t(y) + std::size_t(res[1]) * std::size_t(z))];
    }
};

struct Grid {
    GridGeometry geometry;
    std::vector<std::uint32_t> cell_begin;  ///< cells() + 1 offsets into refs
    std::vector<std::uint32_t> refs;        ///< primitive numbers, sorted within each cell
    float lambda = 0;                       ///< the density actually used (lowered if references overflowed)
    MacroCells macro;
    /// Primitives in no cell, tested by every ray before the walk
    /// (GridConfig::large_primitives_outside).
    std::vector<std::uint32_t> outside;

    bool empty() const { return refs.empty(); }  ///< no cell holds anything (`outside` may)
    std::size_t bytes() const {
        return (cell_begin.size() + refs.size() + outside.size()) * sizeof(std::uint32_t) + macro.full.size();
    }
};

/// Resolution for `n` primitives in a box of extent `e`: about lambda * n
/// near-cubic cells. Axes too thin for one cell get one cell and drop out of
/// the density (a flat scene is gridded by area, a line by length); each
/// axis has at least one cell and the total is at most max_cells.
std::array<int, 3> grid_resolution(const Vec3f& extent, std::size_t n, float lambda, std::size_t max_cells);

}  // namespace raypack
