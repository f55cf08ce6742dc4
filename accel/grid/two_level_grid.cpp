#include "accel/grid/two_level_grid.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "accel/grid/grid_build.h"

namespace raypack {

std::size_t TwoLevelGrid::bytes() const {
    std::size_t b = top.bytes() + cell_grid.size() * sizeof(std::uint32_t) + cells.size() * sizeof(Grid);
    for (const Grid& g : cells) b += g.bytes();
    return b;
}

std::size_t TwoLevelGrid::leaf_cells() const {
    std::size_t n = 0;
    for (const Grid& g : cells) n += g.geometry.cells();
    return n;
}

TwoLevelGrid build_two_level_grid(std::span<const Box3f> boxes, const PrimitiveBoxOverlap& exact,
                                  const TwoLevelGridConfig& config) {
    TwoLevelGrid grid;
    GridConfig top_config;
    top_config.lambda = config.top_lambda;
    grid.top = build_grid(boxes, &exact, top_config);
    if (grid.top.empty()) return grid;
    const GridGeometry& g = grid.top.geometry;
    const std::size_t top_cells = g.cells();
    grid.cell_grid.assign(top_cells, TwoLevelGrid::kNoGrid);
    std::uint32_t count = 0;
    for (std::size_t c = 0; c < top_cells; ++c)
        if (grid.top.cell_begin[c + 1] > grid.top.cell_begin[c]) grid.cell_grid[c] = count++;
    grid.cells.resize(count);

    // The margin the top grid placed its primitives with: rays reach a
    // cell's grid from as far away as they reach the top one.
    const float margin = grid_placement_margin(g.bounds);
    tbb::parallel_for(std::size_t(0), top_cells, [&](std::size_t c) {
        if (grid.cell_grid[c] == TwoLevelGrid::kNoGrid) return;
        const std::uint32_t* prims = grid.top.refs.data() + grid.top.cell_begin[c];
        const std::uint32_t n = grid.top.cell_begin[c + 1] - grid.top.cell_begin[c];
        // The cell's box (widened by the margin), and each primitive's box clipped to it.
        const int x = int(c % std::size_t(g.res[0])), y = int((c / std::size_t(g.res[0])) % std::size_t(g.res[1])),
                  z = int(c / (std::size_t(g.res[0]) * std::size_t(g.res[1])));
        Box3f cell;
        const int index[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
            cell.lo[a] = g.plane(a, index[a]) - margin;
            cell.hi[a] = g.plane(a, index[a] + 1) + margin;
        }
        std::vector<Box3f> clipped(n);
        for (std::uint32_t i = 0; i < n; ++i) {
            clipped[i].lo = max(boxes[prims[i]].lo, cell.lo);
            clipped[i].hi = min(boxes[prims[i]].hi, cell.hi);
        }
        GridConfig cell_config;
        cell_config.lambda = n <= config.max_single_cell ? 1.0f / float(n) : config.cell_lambda;
        cell_config.min_placement_margin = margin;
        const PrimitiveBoxOverlap cell_exact{exact.scene, prims};
        Grid sub = build_grid(clipped, &cell_exact, cell_config);
        for (std::uint32_t& r : sub.refs) r = prims[r];  // back to scene primitive numbers
        grid.cells[grid.cell_grid[c]] = std::move(sub);
    });
    return grid;
}

}  // namespace raypack
