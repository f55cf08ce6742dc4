#pragma once
// A two-level grid (Kalojanov, Billeter and Slusallek, "Two-Level Grids for
// Ray Tracing on GPUs", Eurographics 2011; Jevans and Wyvill's nested grids,
// 1989): a coarse top grid over the scene, and in each of its non-empty
// cells a uniform grid of its own over the primitives there, as fine as
// their number asks. Cells are spent where the primitives are, so a dense
// object in a large empty box (SPD's tree on its ground) no longer crowds
// into a handful of cells.
//
// Both levels are ordinary grids (grid.h), so the 3D-DDA and the coherent
// packet walk run on either: the top walk yields a cell, the cell's grid
// walks its part of the ray.
#include <cstdint>
#include <span>
#include <vector>

#include "accel/grid/grid.h"
#include "accel/grid/primitive_box_overlap.h"

namespace raypack {

/// Densities from raypack's sweeps (docs/structures.md): since the large
/// primitives stay outside and groups walk the cells' grids together
/// (session 31), a top cell per 4 primitives and 2 cells per primitive below
/// run every ray kind fastest, single rays and packets, on tree, teapot and
/// balls (sessions before: single rays at 2 and 2, packets at 1/4 to 1).
struct TwoLevelGridConfig {
    /// Top cells per primitive.
    float top_lambda = 0.25f;
    /// Cells per primitive of each top cell's own grid.
    float cell_lambda = 2.0f;
    /// A top cell with at most this many primitives keeps one cell (a
    /// grid of its own would cost more steps than it saves tests).
    std::uint32_t max_single_cell = 2;
};

struct TwoLevelGrid {
    /// The top grid; its refs are the primitives of each top cell.
    Grid top;
    /// Top cell c's grid is cells[cell_grid[c]]; kNoGrid for an empty cell.
    std::vector<std::uint32_t> cell_grid;
    /// The top cells' grids, their refs scene primitive numbers.
    std::vector<Grid> cells;

    static constexpr std::uint32_t kNoGrid = 0xFFFFFFFFu;
    bool empty() const { return top.empty(); }
    std::size_t bytes() const;
    std::size_t leaf_cells() const;  ///< cells of all second-level grids
};

/// Two-level grid over primitives 0 .. boxes.size() - 1, placed as
/// build_grid() places them (`exact` refines the boxes) at both levels.
TwoLevelGrid build_two_level_grid(std::span<const Box3f> boxes, const PrimitiveBoxOverlap& exact,
                                  const TwoLevelGridConfig& config);

}  // namespace raypack
