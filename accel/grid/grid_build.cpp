#include "accel/grid/grid_build.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_scan.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

namespace raypack {
namespace {

bool usable(const Box3f& b) { return all_finite(b.lo) && all_finite(b.hi) && !b.empty(); }

float max_abs_coord(const Box3f& b) {
    float m = 0;
    for (int a = 0; a < 3; ++a) m = std::max({m, std::fabs(b.lo[a]), std::fabs(b.hi[a])});
    return m;
}

/// The grid's box: the primitives' bounds, an axis of (almost) zero extent
/// widened to the largest cell side so that cells stay near-cubic and
/// non-degenerate (a flat scene), then padded by the placement margin.
GridGeometry make_geometry(const Box3f& bounds, const std::array<int, 3>& res, float margin) {
    GridGeometry g;
    g.res = res;
    const Vec3f e = bounds.extent();
    float side = 0;
    for (int a = 0; a < 3; ++a) side = std::max(side, e[a] / float(res[a]));
    if (!(side > 0)) side = 1e-3f * std::max(1.0f, max_abs_coord(bounds));  // a single point
    Box3f box = bounds;
    for (int a = 0; a < 3; ++a) {
        if (e[a] >= 1e-3f * side) continue;
        const float c = 0.5f * (bounds.lo[a] + bounds.hi[a]);
        box.lo[a] = std::min(bounds.lo[a], c - 0.5f * side);
        box.hi[a] = std::max(bounds.hi[a], c + 0.5f * side);
    }
    for (int a = 0; a < 3; ++a) {
        box.lo[a] -= margin;
        box.hi[a] += margin;
        const float extent = box.hi[a] - box.lo[a];
        g.cell_size[a] = extent / float(res[a]);
        g.inv_cell_size[a] = float(res[a]) / extent;
    }
    g.bounds = box;
    return g;
}

/// The cells one primitive goes into: those its box meets, refined by the
/// exact test, all widened by the margin. Run twice (count, then fill), with
/// the same answers both times.
class CellPlacer {
public:
    CellPlacer(const GridGeometry& g, const PrimitiveBoxOverlap* exact, float margin)
        : g_(g), exact_(exact), margin_(margin) {}

    template <class F>
    void for_each_cell(std::uint32_t prim, const Box3f& box, F&& f) const {
        int i0[3], i1[3];
        for (int a = 0; a < 3; ++a) {
            const double lo = double(g_.bounds.lo[a]), inv = double(g_.inv_cell_size[a]);
            const double last = double(g_.res[a] - 1);
            i0[a] = int(std::clamp(std::floor((double(box.lo[a]) - margin_ - lo) * inv), 0.0, last));
            i1[a] = int(std::clamp(std::floor((double(box.hi[a]) + margin_ - lo) * inv), 0.0, last));
        }
        if (i0[0] == i1[0] && i0[1] == i1[1] && i0[2] == i1[2]) {
            f(g_.cell_index(i0[0], i0[1], i0[2]));
            return;
        }
        for (int z = i0[2]; z <= i1[2]; ++z) {
            for (int y = i0[1]; y <= i1[1]; ++y) {
                for (int x = i0[0]; x <= i1[0]; ++x) {
                    if (exact_ && !exact_->overlaps(prim, cell_lo(x, y, z), cell_hi(x, y, z))) continue;
                    f(g_.cell_index(x, y, z));
                }
            }
        }
    }

private:
    Vec3d cell_lo(int x, int y, int z) const { return corner(x, y, z) - Vec3d{margin_, margin_, margin_}; }
    Vec3d cell_hi(int x, int y, int z) const { return corner(x + 1, y + 1, z + 1) + Vec3d{margin_, margin_, margin_}; }
    Vec3d corner(int x, int y, int z) const {
        const Vec3d lo(g_.bounds.lo), cs(g_.cell_size);
        return {lo.x + double(x) * cs.x, lo.y + double(y) * cs.y, lo.z + double(z) * cs.z};
    }

    const GridGeometry& g_;
    const PrimitiveBoxOverlap* exact_;
    double margin_;
};

template <class Body>
void for_each_prim(std::span<const Box3f> boxes, Body&& body) {
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(boxes.size()), 64), [&](const auto& r) {
        for (std::uint32_t p = r.begin(); p != r.end(); ++p)
            if (usable(boxes[p])) body(p);
    });
}

/// Count pass and prefix sum: begin[c] becomes the end of cell c's range
/// (an inclusive scan), begin[cells] the total, which is returned.
std::uint64_t count_references(std::span<const Box3f> boxes, const CellPlacer& placer, std::vector<std::uint32_t>& begin) {
    for_each_prim(boxes, [&](std::uint32_t p) {
        placer.for_each_cell(p, boxes[p], [&](std::uint32_t c) {
            std::atomic_ref<std::uint32_t>(begin[c]).fetch_add(1, std::memory_order_relaxed);
        });
    });
    return tbb::parallel_scan(
        tbb::blocked_range<std::size_t>(0, begin.size(), 1 << 16), std::uint64_t(0),
        [&](const tbb::blocked_range<std::size_t>& r, std::uint64_t sum, bool is_final) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                sum += begin[i];
                if (is_final) begin[i] = std::uint32_t(sum);  // wraps only if the total overflows; then rejected
            }
            return sum;
        },
        std::plus<std::uint64_t>());
}

}  // namespace

float grid_placement_margin(const Box3f& bounds) {
    const Vec3f e = bounds.extent();
    const float largest = std::max({e.x, e.y, e.z, 0.0f});
    return 1e-5f * largest + 8.0f * std::numeric_limits<float>::epsilon() * max_abs_coord(bounds);
}

Grid build_grid(std::span<const Box3f> boxes, const PrimitiveBoxOverlap* exact, const GridConfig& config) {
    Grid grid;
    if (boxes.size() >= std::numeric_limits<std::uint32_t>::max()) throw std::length_error("grid: too many primitives");
    Box3f bounds;
    std::size_t n = 0;
    for (const Box3f& b : boxes) {
        if (!usable(b)) continue;
        bounds.extend(b);
        ++n;
    }
    if (n == 0) return grid;

    // Cell indices are 32-bit; references must fit 32-bit offsets.
    const std::size_t max_cells = std::min<std::size_t>(config.max_cells, std::size_t(1) << 31);
    const std::uint64_t max_refs =
        std::min<std::uint64_t>(config.max_references, std::numeric_limits<std::uint32_t>::max() - 1);
    std::array<int, 3> res = grid_resolution(bounds.extent(), n, config.lambda, max_cells);
    const float margin = std::max(grid_placement_margin(bounds), config.min_placement_margin);
    std::vector<std::uint32_t>& begin = grid.cell_begin;
    std::uint64_t total = 0;
    for (;;) {
        grid.geometry = make_geometry(bounds, res, margin);
        begin.assign(grid.geometry.cells() + 1, 0);
        total = count_references(boxes, CellPlacer(grid.geometry, exact, margin), begin);
        if (total <= max_refs || grid.geometry.cells() == 1) break;
        // Too many references (huge, overlapping primitives): coarser cells.
        for (int& r : res) r = std::max(1, r / 2);
    }
    if (total > std::numeric_limits<std::uint32_t>::max() - 1)
        throw std::length_error("grid: more references than 32-bit offsets can address");
    grid.lambda = float(double(grid.geometry.cells()) / double(n));

    // Fill pass: each reference takes the last free slot of its cell, so that
    // begin[c] ends at the start of cell c.
    grid.refs.resize(total);
    const CellPlacer placer(grid.geometry, exact, margin);
    for_each_prim(boxes, [&](std::uint32_t p) {
        placer.for_each_cell(p, boxes[p], [&](std::uint32_t c) {
            const std::uint32_t slot = std::atomic_ref<std::uint32_t>(begin[c]).fetch_sub(1, std::memory_order_relaxed);
            grid.refs[slot - 1] = p;
        });
    });
    // Threads filled cells in any order: sort, for answers that do not depend
    // on the schedule (ties between primitives at the same t) and for memory order.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid.geometry.cells(), 4096), [&](const auto& r) {
        for (std::size_t c = r.begin(); c != r.end(); ++c)
            if (begin[c + 1] - begin[c] > 1) std::sort(grid.refs.begin() + begin[c], grid.refs.begin() + begin[c + 1]);
    });
    build_macrocells(grid);
    return grid;
}

void build_macrocells(Grid& grid) {
    MacroCells& m = grid.macro;
    const GridGeometry& g = grid.geometry;
    for (int a = 0; a < 3; ++a) m.res[a] = ((g.res[a] - 1) >> m.shift) + 1;
    m.full.assign(std::size_t(m.res[0]) * std::size_t(m.res[1]) * std::size_t(m.res[2]), 0);
    // One layer of blocks per task: no two tasks write the same block.
    tbb::parallel_for(0, m.res[2], [&](int layer) {
        const int z1 = std::min(g.res[2], (layer + 1) << m.shift);
        for (int z = layer << m.shift; z < z1; ++z)
            for (int y = 0; y < g.res[1]; ++y)
                for (int x = 0; x < g.res[0]; ++x) {
                    const std::uint32_t c = g.cell_index(x, y, z);
                    if (grid.cell_begin[c] == grid.cell_begin[c + 1]) continue;
                    const std::size_t row = std::size_t(y >> m.shift) + std::size_t(m.res[1]) * std::size_t(layer);
                    m.full[std::size_t(x >> m.shift) + std::size_t(m.res[0]) * row] = 1;
                }
    });
}

}  // namespace raypack
