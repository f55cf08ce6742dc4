#pragma once
// 3D-DDA through a uniform grid (Amanatides & Woo, "A Fast Voxel Traversal
// Algorithm for Ray Tracing", Eurographics 1987), as a small iterator after
// pbrt-v4's DDAMajorantIterator: next() yields the cells a ray crosses, front
// to back, each with the parametric interval it spends there.
//
// One iterator is the whole per-ray state; dda_packet.h runs the same walk
// in K lanes, each stepping independently.
//
// Robustness choices:
// - The crossing distance of the k-th plane is t_first + k * tDelta with one
//   fused multiply-add, instead of accumulating tDelta k times: its error
//   stays a few ulps of t however many cells are crossed.
// - A direction component below kMinRcpInput in magnitude (including +-0)
//   never steps along its axis, just as the robust slab test treats it as
//   parallel; its crossing distance is +infinity.
// - Start indices are clamped into the grid, so an entry point that rounds
//   onto or past the far boundary starts in the last cell.
// Where rounding makes the walk differ from the exact one, it does so within
// a few ulps of t of a cell plane; the builder widens cells by a margin that
// covers this (grid_build.h).
//
// `--slabs plain` (SlabTag<Plain>): the cell planes are slab planes too, so
// their first crossings t_first use the plain form p * rdir - org * rdir
// like the root clip (cell_kernel_variants.h); tDelta and the stepping rule
// for parallel axes are the walk's own and stay as they are.
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "accel/cell_kernel_variants.h"
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
    /// reciprocal(dir, rcp), computed once by the caller for the slab test too.
    template <SlabMethod S = SlabMethod::Robust>
    RAYPACK_INLINE GridDda(const GridGeometry& g, const Vec3f& org, const Vec3f& dir, const Vec3f& inv_dir,
                           float t_start, SlabTag<S> = {})
        : t_enter_(t_start) {
        const Vec3f p = org + dir * t_start;
        std::int32_t stride = 1;
        for (int a = 0; a < 3; ++a) {
            // Cell of the start point; the comparisons also send NaN to cell 0.
            const float last = float(g.res[a] - 1);
            float f = (p[a] - g.bounds.lo[a]) * g.inv_cell_size[a];
            f = f > 0.0f ? f : 0.0f;
            f = f < last ? f : last;
            const int i = int(f);
            cell_ += i * stride;
            steps_[a] = 0;
            if (std::fabs(dir[a]) < kMinRcpInput || !(dir[a] == dir[a])) {
                left_[a] = 0;
                stride_[a] = 0;
                t_first_[a] = t_next_[a] = std::numeric_limits<float>::infinity();
                t_delta_[a] = 0;
            } else {
                const bool up = dir[a] > 0;
                left_[a] = up ? g.res[a] - 1 - i : i;
                stride_[a] = up ? stride : -stride;
                t_first_[a] = t_next_[a] =
                    plane_distance<S>(g.plane(a, up ? i + 1 : i), org[a], inv_dir[a], org[a] * inv_dir[a]);
                t_delta_[a] = g.cell_size[a] * std::fabs(inv_dir[a]);
            }
            stride *= g.res[a];
        }
    }

    /// The current cell, then a step to the next; nullopt once the ray has
    /// left the grid.
    RAYPACK_INLINE std::optional<DdaSegment> next() {
        if (done_) return std::nullopt;
        DdaSegment seg{std::uint32_t(cell_), t_enter_, 0.0f};
        // Cross the nearest plane. One branch per axis, so that the state
        // stays in registers (indexing it by a variable axis would not).
        if (t_next_[0] < t_next_[1]) {
            if (t_next_[0] < t_next_[2]) step<0>(seg);
            else step<2>(seg);
        } else {
            if (t_next_[1] < t_next_[2]) step<1>(seg);
            else step<2>(seg);
        }
        return seg;
    }

private:
    template <int A>
    RAYPACK_INLINE void step(DdaSegment& seg) {
        seg.t_exit = t_next_[A];
        if (left_[A] == 0) {  // also every axis parallel: the ray stays in this cell
            done_ = true;
            return;
        }
        --left_[A];
        cell_ += stride_[A];
        t_enter_ = t_next_[A];
        // Plane k along the axis is crossed at t_first + k * t_delta: one
        // rounding of a product, not k roundings of a running sum, so the
        // error stays a few ulps of t however far the walk goes.
        steps_[A] += 1.0f;
        t_next_[A] = std::fma(steps_[A], t_delta_[A], t_first_[A]);
    }

    float t_enter_;
    float t_next_[3], t_first_[3], t_delta_[3], steps_[3];
    std::int32_t left_[3];    ///< planes still to cross along each axis before leaving the grid
    std::int32_t stride_[3];  ///< change of the linear cell index per step
    std::int32_t cell_ = 0;
    bool done_ = false;
};

}  // namespace raypack
