#pragma once
// 3D-DDA through a uniform grid (Amanatides & Woo, "A Fast Voxel Traversal
// Algorithm for Ray Tracing", Eurographics 1987), as a small iterator after
// pbrt-v4's DDAMajorantIterator: next() yields the cells a ray crosses, front
// to back, each with the parametric interval it spends there.
//
// One iterator is the whole per-ray state, so a K-wide traversal can give
// each lane its own and step them independently.
//
// Robustness choices:
// - The crossing distance of the next plane is computed afresh from the cell
//   index at every step, t = (plane - org) / dir, instead of accumulating
//   tDelta: its error stays a few ulps however many cells are crossed.
// - A direction component below kMinRcpInput in magnitude (including +-0)
//   never steps along its axis, just as the robust slab test treats it as
//   parallel; its crossing distance is +infinity.
// - Start indices are clamped into the grid, so an entry point that rounds
//   onto or past the far boundary starts in the last cell.
// Where rounding makes the walk differ from the exact one, it does so within
// a few ulps of t of a cell plane; the builder widens cells by a margin that
// covers this (grid_build.h).
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "accel/grid/grid.h"

namespace raypack {

/// One cell of a ray's walk and the interval [t_enter, t_exit] spent in it.
struct DdaSegment {
    std::uint32_t cell;
    float t_enter, t_exit;
};

class GridDda {
public:
    /// Walk of the ray (org, dir) from parameter t_start, which should lie in
    /// the grid's box (the entry distance of the slab test). `inv_dir` is
    /// reciprocal(dir), computed once by the caller for the slab test too.
    RAYPACK_INLINE GridDda(const GridGeometry& g, const Vec3f& org, const Vec3f& dir, const Vec3f& inv_dir,
                           float t_start)
        : g_(&g), org_(org), inv_dir_(inv_dir), t_enter_(t_start) {
        const Vec3f p = org + dir * t_start;
        std::int32_t stride = 1;
        cell_ = 0;
        for (int a = 0; a < 3; ++a) {
            // Cell of the start point; the comparisons also send NaN to cell 0.
            const float last = float(g.res[a] - 1);
            float f = (p[a] - g.bounds.lo[a]) * g.inv_cell_size[a];
            f = f > 0.0f ? f : 0.0f;
            f = f < last ? f : last;
            idx_[a] = int(f);
            cell_ += idx_[a] * stride;
            if (std::fabs(dir[a]) < kMinRcpInput || !(dir[a] == dir[a])) {
                step_[a] = 0;
                end_[a] = -2;  // never reached
                t_next_[a] = std::numeric_limits<float>::infinity();
            } else if (dir[a] > 0) {
                step_[a] = 1;
                end_[a] = g.res[a];
                t_next_[a] = crossing(a, idx_[a] + 1);
            } else {
                step_[a] = -1;
                end_[a] = -1;
                t_next_[a] = crossing(a, idx_[a]);
            }
            stride_[a] = step_[a] * stride;
            stride *= g.res[a];
        }
    }

    /// The current cell, then a step to the next; nullopt once the ray has
    /// left the grid.
    RAYPACK_INLINE std::optional<DdaSegment> next() {
        if (done_) return std::nullopt;
        // Axis of the nearest plane crossing.
        const int a = t_next_[0] < t_next_[1] ? (t_next_[0] < t_next_[2] ? 0 : 2) : (t_next_[1] < t_next_[2] ? 1 : 2);
        const DdaSegment seg{std::uint32_t(cell_), t_enter_, t_next_[a]};
        idx_[a] += step_[a];
        if (idx_[a] == end_[a] || step_[a] == 0 || !(t_next_[a] < std::numeric_limits<float>::infinity())) {
            done_ = true;
        } else {
            cell_ += stride_[a];
            t_enter_ = t_next_[a];
            t_next_[a] = crossing(a, step_[a] > 0 ? idx_[a] + 1 : idx_[a]);
        }
        return seg;
    }

    /// Cell coordinates of the current cell (for tests and statistics).
    int index(int axis) const { return idx_[axis]; }

private:
    /// Parameter at which the ray crosses plane i of `axis`.
    RAYPACK_INLINE float crossing(int axis, int i) const { return (g_->plane(axis, i) - org_[axis]) * inv_dir_[axis]; }

    const GridGeometry* g_;
    Vec3f org_, inv_dir_;
    float t_enter_;
    float t_next_[3];
    int idx_[3], step_[3], end_[3];
    std::int32_t stride_[3];
    std::int32_t cell_;
    bool done_ = false;
};

}  // namespace raypack
