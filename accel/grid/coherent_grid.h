#pragma once
// Coherent grid traversal (Wald, Ize, Kensler, Knoll and Parker, "Ray
// Tracing Animated Scenes using Coherent Grid Traversal", SIGGRAPH 2006):
// a packet whose rays all travel the same way along one axis (the major
// axis k) walks the grid slice by slice across k. In each slice it visits
// the rectangle of cells that the packet's ray segments span there, and
// tests each primitive of those cells once for all its lanes; a per-packet
// mailbox keeps a primitive met again in a later cell from being re-tested.
// The per-lane 3D-DDA (dda_packet.h) steps every lane through its own cells;
// here the stepping is shared and only the rectangle is per slice.
//
// Included only by grid_packet.cpp and grid2_accel.cpp.
//
// Exactness: every primitive in a cell some active lane's segment crosses
// is tested against every active lane, over the lane's whole [tnear, tfar],
// so each lane's closest hit is the minimum over a superset of the cells its
// single-ray walk visits. The rectangle is widened by a margin that covers
// the rounding of the lanes' positions (and the builder's cells are widened
// too, grid_build.h); a lane stops only once its closest hit lies clearly
// before the far plane of the slice just done. Ties between primitives at
// exactly the same t may resolve to another primitive than the single-ray
// walk's (another test order).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "accel/grid/grid.h"
#include "accel/packet_intersector.h"
#include "kernels/ray_packet.h"
#include "kernels/simd.h"

namespace raypack::coherent_grid {

/// Margins, in cells: the cell of a coordinate is rounded outwards by this
/// much, on top of a relative margin on the coordinates themselves.
inline constexpr float kCellMargin = 1e-3f;
inline constexpr float kRelativeMargin = 0x1p-19f;

/// Index range [first, last] of the cells along one axis that cover
/// [lo, hi] (world coordinates), widened by the margins and clamped.
RAYPACK_INLINE void cell_span(float lo, float hi, float grid_lo, float inv_cell, int res, int& first, int& last) {
    const float lo_cell = (lo - grid_lo) * inv_cell - kCellMargin;
    const float hi_cell = (hi - grid_lo) * inv_cell + kCellMargin;
    // Comparisons before the conversion: NaN and huge values clamp safely.
    const float top = float(res - 1);
    first = lo_cell > 0.0f ? (lo_cell < top ? int(lo_cell) : res - 1) : 0;
    last = hi_cell > 0.0f ? (hi_cell < top ? int(hi_cell) : res - 1) : 0;
}

/// The major axis of a packet and whether it can walk coherently: every
/// active lane's direction has the same sign along the axis of the first
/// lane's largest direction component, and none is too small to invert.
/// Returns -1 if not.
template <int K>
RAYPACK_INLINE int major_axis(const RayPacket<K>& ray, const vmask<K>& active) {
    const std::uint32_t bits = mask_bits(active);
    const int l = std::countr_zero(bits);
    alignas(64) float d[3][K];
    for (int a = 0; a < 3; ++a) ray.dir[a].store_aligned(d[a]);
    const float ax = std::fabs(d[0][l]), ay = std::fabs(d[1][l]), az = std::fabs(d[2][l]);
    const int k = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
    const vfloat<K> tiny(1e-6f);
    const vmask<K> same = d[k][l] > 0.0f ? ray.dir[k] > tiny : ray.dir[k] < -tiny;
    return (mask_bits(same) & bits) == bits ? k : -1;
}

/// Whether a macrocell of layer `block` along axis k under the cells
/// [first, last] (along the axes after k) holds any reference.
RAYPACK_INLINE bool any_macrocell(const MacroCells& macro, int k, int block, const int first[2], const int last[2]) {
    const int u = (k + 1) % 3, v = (k + 2) % 3;
    for (int j = first[1] >> macro.shift; j <= last[1] >> macro.shift; ++j)
        for (int i = first[0] >> macro.shift; i <= last[0] >> macro.shift; ++i) {
            int c[3];
            c[k] = block, c[u] = i, c[v] = j;
            if (macro.any(c[0], c[1], c[2])) return true;
        }
    return false;
}

/// Cells per active lane above which a slice's rectangle ends the coherent
/// walk: the lanes then diverge, and stepping each lane's own DDA visits
/// fewer cells than the rectangle holds. Measured (docs/structures.md): 2,
/// 4 and 8 trace camera rays alike; 2 is best for shadow rays.
inline constexpr int kMaxCellsPerLane = 2;

/// The slice loop of both coherent walks (a packet, walk(); a group,
/// coherent_grid_group.h), from slice s along axis k, upwards if `up`:
/// a block of slices (one layer of macrocells) is skipped whole if the
/// macrocells its rectangle meets are empty; otherwise slice by slice,
/// `rectangle(i0, i1, first, last)` bounds the cells the lanes cross between
/// planes i0 and i1 (false: no lane there), `diverged(s, cells)` ends the
/// walk (false) when the rectangle holds too many cells, `visit_cells(s,
/// first, last)` visits them (true: no lane left), and `stop_before(i)`
/// drops the lanes done before plane i (true: none left). Returns true when
/// the walk is done.
template <class Rectangle, class Diverged, class VisitCells, class StopBefore>
RAYPACK_INLINE bool walk_slices(const Grid& grid, int k, bool up, int s, Rectangle&& rectangle, Diverged&& diverged,
                                VisitCells&& visit_cells, StopBefore&& stop_before) {
    const MacroCells& macro = grid.macro;
    const int res_k = grid.geometry.res[k];
    const int step = up ? 1 : -1;
    while (s >= 0 && s < res_k) {
        const int block = s >> macro.shift;
        const int block_end = up ? std::min(res_k - 1, ((block + 1) << macro.shift) - 1) : block << macro.shift;
        int first[2], last[2];
        const bool full = rectangle(std::min(s, block_end), std::max(s, block_end) + 1, first, last) &&
                          any_macrocell(macro, k, block, first, last);
        if (!full) {
            if (stop_before(up ? block_end + 1 : block_end)) return true;
            s = block_end + step;
            continue;
        }
        for (;; s += step) {
            if (!rectangle(s, s + 1, first, last)) first[1] = last[1] + 1;  // no lane in this slice: no cells
            const int cells = (last[0] - first[0] + 1) * std::max(0, last[1] - first[1] + 1);
            if (diverged(s, cells)) return false;
            if (visit_cells(s, first, last)) return true;
            if (stop_before(up ? s + 1 : s)) return true;
            if (s == block_end) break;
        }
        s = block_end + step;
    }
    return true;
}

/// Walks the active lanes through the grid slice by slice along axis k
/// (from major_axis), from each lane's `entry` distance into the grid's box,
/// calling `visit_cell(c)` for each non-empty cell c met, which tests what
/// the cell holds against the active lanes and returns true once no lane is
/// left (any hit). Returns true when the packet is done; false when its rays
/// diverged, with `active` the lanes still walking and `entry` where each
/// should go on alone.
template <int K, class VisitCell>
bool walk(const Grid& grid, int k, const RayPacket<K>& ray, vmask<K>& active, vfloat<K>& entry,
          VisitCell&& visit_cell) {
    using F = vfloat<K>;
    const GridGeometry& g = grid.geometry;
    const MacroCells& macro = grid.macro;
    const int u = (k + 1) % 3, v = (k + 2) % 3;
    const F inf(std::numeric_limits<float>::infinity());
    const F rel(kRelativeMargin);

    // Where each lane leaves the grid's box: the nearest far face.
    F exit = inf;
    for (int a = 0; a < 3; ++a) {
        const F t0 = (F(g.bounds.lo[a]) - ray.org[a]) * ray.rdir[a];
        const F t1 = (F(g.bounds.hi[a]) - ray.org[a]) * ray.rdir[a];
        const F far = vmax(t0, t1);
        exit = vmin(exit, select(far == far, far, inf));  // 0 * inf (on a face, parallel): no bound
    }
    exit = exit + vabs(exit) * rel;

    // First slice: the one holding the first lane to enter (along k).
    const bool up = (mask_bits(ray.dir[k] > F(0.0f)) & mask_bits(active)) != 0;
    const F start_cell = (ray.org[k] + ray.dir[k] * entry - F(g.bounds.lo[k])) * F(g.inv_cell_size[k]);
    const float first_cell = up ? lane_min<K>(select(active, start_cell, inf)) - kCellMargin
                                : lane_max<K>(select(active, start_cell, -inf)) + kCellMargin;
    const int res_k = g.res[k];
    const int s = first_cell > 0.0f ? (first_cell < float(res_k - 1) ? int(first_cell) : res_k - 1) : 0;

    const std::int32_t stride[3] = {1, g.res[0], g.res[0] * g.res[1]};
    const std::uint32_t* begin = grid.cell_begin.data();

    const F org_k = ray.org[k], rdir_k = ray.rdir[k];
    // Distance of each lane to the plane between slices i - 1 and i.
    auto plane_t = [&](int i) RAYPACK_INLINE_LAMBDA { return (F(g.plane(k, i)) - org_k) * rdir_k; };

    const int axes[2] = {u, v};
    {
        // Rays whose directions spread apart by more than about half a cell
        // per slice (bounces off a surface, say) would outgrow the lanes
        // within a few slices: they step their own DDAs from the start.
        float widen[2];
        for (int i = 0; i < 2; ++i) {
            const F slope = ray.dir[axes[i]] * rdir_k;
            widen[i] = (lane_max<K>(select(active, slope, -inf)) - lane_min<K>(select(active, slope, inf))) *
                       g.cell_size[k] * g.inv_cell_size[axes[i]];
        }
        const float ahead = float(1 << macro.shift);
        if (!((1.0f + ahead * widen[0]) * (1.0f + ahead * widen[1]) <=
              float(kMaxCellsPerLane * std::popcount(mask_bits(active)))))
            return false;
    }
    // The cells [first, last] along u and v that the lanes' segments cross
    // between the planes i0 and i1, each segment clipped to the lane's entry,
    // exit and closest hit so far; false if no lane has one there.
    auto rectangle = [&](int i0, int i1, int first[2], int last[2]) RAYPACK_INLINE_LAMBDA {
        const F t0 = plane_t(i0), t1 = plane_t(i1);
        const F ta = vmax(vmin(t0, t1), entry), tb = vmin(vmax(t0, t1), vmin(ray.tfar, exit));
        const vmask<K> part = active & (ta <= tb);
        if (none(part)) return false;
        for (int i = 0; i < 2; ++i) {
            const int a = axes[i];
            const F pa = ray.org[a] + ray.dir[a] * ta, pb = ray.org[a] + ray.dir[a] * tb;
            const F slack = (vabs(ray.org[a]) + vabs(pa) + vabs(pb)) * rel;
            const F lo = vmin(pa, pb) - slack, hi = vmax(pa, pb) + slack;
            cell_span(lane_min<K>(select(part, lo, inf)), lane_max<K>(select(part, hi, -inf)), g.bounds.lo[a],
                      g.inv_cell_size[a], g.res[a], first[i], last[i]);
        }
        return true;
    };
    // Lanes whose segment (up to the closest hit so far) ends clearly before
    // plane i stop; true if none walks on.
    auto stop_before = [&](int i) RAYPACK_INLINE_LAMBDA {
        const F t_out = plane_t(i);
        const F end = vmin(ray.tfar, exit);
        active = active & !(end + (vabs(end) + vabs(t_out)) * rel < t_out);
        return none(active);
    };

    return walk_slices(
        grid, k, up, s, rectangle,
        [&](int slice, int cells) RAYPACK_INLINE_LAMBDA {
            if (cells <= kMaxCellsPerLane * std::popcount(mask_bits(active))) return false;
            entry = vmax(entry, plane_t(up ? slice : slice + 1));
            return true;
        },
        [&](int slice, const int first[2], const int last[2]) RAYPACK_INLINE_LAMBDA {
            const std::uint32_t* row = begin + slice * stride[k] + first[1] * stride[v] + first[0] * stride[u];
            for (int j = first[1]; j <= last[1]; ++j, row += stride[v]) {
                const std::uint32_t* cell = row;
                for (int i = first[0]; i <= last[0]; ++i, cell += stride[u])
                    if (cell[0] != cell[1] && visit_cell(std::uint32_t(cell - begin))) return true;
            }
            return false;
        },
        stop_before);
}

/// walk() testing each cell's primitives against the active lanes, each
/// primitive once per packet (a direct-mapped mailbox). AnyHit: lanes that
/// hit are added to `occluded` and stop.
template <int K, bool AnyHit>
bool trace(const Grid& grid, const PacketRecordIntersector<vfloat<K>>& isect, int k, RayPacket<K>& ray,
           HitPacket<K>& hit, vmask<K>& active, vfloat<K>& entry, vmask<K>& occluded) {
    constexpr std::uint32_t kMailboxSize = 128;
    alignas(64) std::uint32_t mailbox[kMailboxSize];
    std::fill(mailbox, mailbox + kMailboxSize, kNoPrim);
    const std::uint32_t* begin = grid.cell_begin.data();
    const std::uint32_t* refs = grid.refs.data();
    return walk<K>(grid, k, ray, active, entry, [&](std::uint32_t c) RAYPACK_INLINE_LAMBDA {
        for (std::uint32_t r = begin[c], r_end = begin[c + 1]; r < r_end; ++r) {
            const std::uint32_t prim = refs[r];
            std::uint32_t& slot = mailbox[prim & (kMailboxSize - 1)];
            if (slot == prim) continue;
            slot = prim;
            const vmask<K> m = isect.intersect(active, ray, hit, prim);
            if constexpr (AnyHit) {
                if (any(m)) {
                    occluded = occluded | m;
                    active = active & !m;
                    if (none(active)) return true;
                }
            }
        }
        return false;
    });
}

}  // namespace raypack::coherent_grid
