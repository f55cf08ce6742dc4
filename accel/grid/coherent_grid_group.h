#pragma once
// Coherent grid traversal for a group of packets: up to G packets of K rays
// walk the grid together, slice by slice along their shared major axis.
// Wald, Ize, Kensler, Knoll and Parker (SIGGRAPH 2006) trace frusta of many
// rays at once so that the per-slice work (the rectangle of cells, the
// macrocell test, the loop over the cells and the mailbox) is paid once for
// all of them; coherent_grid.h walks one packet of K rays, whose rectangle
// in a slice is already a few cells wide because each ray's own segment in
// a slice spans about a cell along a diagonal. A group visits the union of
// its packets' rectangles once.
//
// Each primitive of a cell is tested against the packets whose own
// rectangle in the slice holds the cell (the others cannot cross it there),
// once per packet: the mailbox keeps, per primitive, the packets already
// tested.
// Exactness is coherent_grid.h's: every cell a lane's segment crosses lies
// in the group's rectangle of that slice, and the lane's packet is tested
// against everything in it.
//
// Included only by grid_packet.cpp and grid2_accel.cpp.
#include <bit>
#include <cstdint>
#include <limits>

#include "accel/grid/coherent_grid.h"
#include "accel/grid/grid_lanes_walk.h"
#include "accel/packet_driver.h"

namespace raypack::coherent_grid {

/// Rays per group of coherent packets: 128 rays (8 packets of 16, two 8 x 8
/// tiles of `raypack rays`) traced camera and shadow rays as fast as 256 and
/// up to 1.08x as fast as 64 (docs/structures.md).
inline constexpr int kGroupRays = 128;

/// Packets per group of packets of K rays from one point (camera rays): in
/// packets of 16, 32 (512 rays, the most a 32-bit set of packets holds),
/// since a slice's work for the packets (their cell ranges, their ends) is
/// done eight packets at a time: camera rays 1.01-1.11x as fast as in
/// groups of 128 rays, while shadow rays lost 3-6% in groups of 512; in
/// packets of 8, 256 rays were 0.94-0.99x as fast as 128 (docs/structures.md).
template <int K>
inline constexpr int kOnePointGroupPackets = K == 16 ? 32 : kGroupRays / K;

/// Whether the valid lanes of the packets p[0, count) all leave one point.
template <int K>
bool from_one_point(const LoadedPacket<K>* p, int count) {
    for (int q = 0; q < count; ++q) {
        if (!one_origin<K>(p[q])) return false;  // also false without a valid lane
        for (int a = 0; a < 3; ++a)
            if (lane(p[q].ray.org[a], std::countr_zero(mask_bits(p[q].valid))) !=
                lane(p[0].ray.org[a], std::countr_zero(mask_bits(p[0].valid))))
                return false;
    }
    return true;
}

/// Per-primitive record of the packets of a group already tested against
/// it (direct-mapped; a collision forgets, which only repeats a test).
class GroupMailbox {
public:
    GroupMailbox() { std::fill(std::begin(prim_), std::end(prim_), kNoPrim); }
    RAYPACK_INLINE std::uint32_t& tested(std::uint32_t prim) {
        const std::uint32_t slot = prim & (kSlots - 1);
        if (prim_[slot] != prim) prim_[slot] = prim, packets_[slot] = 0;
        return packets_[slot];
    }

private:
    static constexpr std::uint32_t kSlots = 256;
    std::uint32_t prim_[kSlots], packets_[kSlots];
};

/// The packets of a group that walk together: the rays and hits of each,
/// the lanes still walking and where each enters the grid.
template <int K, int G>
struct GroupLanes {
    LoadedPacket<K>* packet[G];
    vmask<K> active[G];
    vfloat<K> entry[G];
    int count = 0;
};

/// The packets of p[0, count) that meet the grid's box, with their lanes
/// that do and where they enter it.
template <int K, int G, SlabMethod Slabs>
RAYPACK_INLINE void enter_group(const Grid& grid, LoadedPacket<K>* p, int count, GroupLanes<K, G>& lanes) {
    for (int q = 0; q < count; ++q) {
        vfloat<K> entry;
        const vmask<K> active = grid_lanes::enter_grid<K, Slabs>(grid, p[q].ray, p[q].valid, entry);
        if (none(active)) continue;
        lanes.packet[lanes.count] = &p[q];
        lanes.active[lanes.count] = active;
        lanes.entry[lanes.count++] = entry;
    }
}

/// The major axis every active lane of the group travels along in one
/// direction (that of the first packet's first lane), or -1.
template <int K, int G>
int group_major_axis(const GroupLanes<K, G>& lanes) {
    if (lanes.count == 0) return -1;
    const int k = major_axis<K>(lanes.packet[0]->ray, lanes.active[0]);
    if (k < 0) return -1;
    const bool up = any(lanes.active[0] & (lanes.packet[0]->ray.dir[k] > vfloat<K>(0.0f)));
    const vfloat<K> tiny(1e-6f);
    for (int q = 1; q < lanes.count; ++q) {
        const vfloat<K> d = lanes.packet[q]->ray.dir[k];
        const std::uint32_t a = mask_bits(lanes.active[q]);
        if ((mask_bits(up ? d > tiny : d < -tiny) & a) != a) return -1;
    }
    return k;
}

/// walk() for a group: the major axis k and its sign are shared by every
/// active lane of every packet (the caller checks). `visit_cell(c, packets,
/// walking, changed)` tests cell c against the packets of the bit set
/// `packets` (those whose own rectangle in the slice holds the cell), adds
/// to `changed` those whose lanes found closer hits or stopped, clears in
/// `walking` the packets left without lanes, and returns true once none is.
/// Returns true when the group is done; false when its rays spread too far
/// apart, with each packet's active lanes and entries set for it to go on
/// alone.
template <int K, int G, class VisitCell>
bool walk_group(const Grid& grid, int k, GroupLanes<K, G>& lanes, VisitCell&& visit_cell) {
    using F = vfloat<K>;
    const GridGeometry& g = grid.geometry;
    const MacroCells& macro = grid.macro;
    const int u = (k + 1) % 3, v = (k + 2) % 3;
    const int axes[2] = {u, v};
    const F inf(std::numeric_limits<float>::infinity());
    const F rel(kRelativeMargin);
    const int n = lanes.count;

    const RayPacket<K>& first_ray = lanes.packet[0]->ray;
    const bool up = (mask_bits(first_ray.dir[k] > F(0.0f)) & mask_bits(lanes.active[0])) != 0;
    F exit[G];
    std::uint32_t walking = 0;  // packets with lanes still walking
    int lane_count = 0;
    float first_cell = up ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
    float slope_lo[2], slope_hi[2];
    slope_lo[0] = slope_lo[1] = std::numeric_limits<float>::infinity();
    slope_hi[0] = slope_hi[1] = -std::numeric_limits<float>::infinity();
    // Rays from one point (a pinhole camera's): a packet's lanes cross the
    // planes of a slice within the lines of its extreme slopes from that
    // point, so its rectangle there takes a few scalar products, not a
    // vector pass over its lanes and four reductions.
    bool one_point = n > 0;
    float origin[3] = {0, 0, 0};
    alignas(32) float packet_slope_lo[2][G], packet_slope_hi[2][G];
    for (int i = 0; i < 2; ++i) std::fill(packet_slope_lo[i], packet_slope_lo[i] + G, 0.0f);
    for (int i = 0; i < 2; ++i) std::fill(packet_slope_hi[i], packet_slope_hi[i] + G, 0.0f);
    auto packet_slopes = [&](int q) RAYPACK_INLINE_LAMBDA {
        const RayPacket<K>& ray = lanes.packet[q]->ray;
        const vmask<K> a = lanes.active[q];
        for (int i = 0; i < 2; ++i) {
            const F slope = ray.dir[axes[i]] * ray.rdir[k];
            packet_slope_lo[i][q] = lane_min<K>(select(a, slope, inf));
            packet_slope_hi[i][q] = lane_max<K>(select(a, slope, -inf));
        }
    };
    for (int q = 0; q < n && one_point; ++q) {
        const RayPacket<K>& ray = lanes.packet[q]->ray;
        const vmask<K> a = lanes.active[q];
        for (int axis = 0; axis < 3; ++axis) {
            const float o_lo = lane_min<K>(select(a, ray.org[axis], inf));
            if (q == 0) origin[axis] = o_lo;
            one_point = one_point && o_lo == origin[axis] && lane_max<K>(select(a, ray.org[axis], -inf)) == o_lo;
        }
    }
    for (int q = 0; q < n; ++q) {
        const RayPacket<K>& ray = lanes.packet[q]->ray;
        const vmask<K> a = lanes.active[q];
        F e = inf;
        for (int axis = 0; axis < 3; ++axis) {
            const F t0 = (F(g.bounds.lo[axis]) - ray.org[axis]) * ray.rdir[axis];
            const F t1 = (F(g.bounds.hi[axis]) - ray.org[axis]) * ray.rdir[axis];
            const F far = vmax(t0, t1);
            e = vmin(e, select(far == far, far, inf));
        }
        exit[q] = e + vabs(e) * rel;
        const F start = (ray.org[k] + ray.dir[k] * lanes.entry[q] - F(g.bounds.lo[k])) * F(g.inv_cell_size[k]);
        first_cell = up ? std::min(first_cell, lane_min<K>(select(a, start, inf)))
                        : std::max(first_cell, lane_max<K>(select(a, start, -inf)));
        packet_slopes(q);
        for (int i = 0; i < 2; ++i) {
            slope_lo[i] = std::min(slope_lo[i], packet_slope_lo[i][q]);
            slope_hi[i] = std::max(slope_hi[i], packet_slope_hi[i][q]);
        }
        walking |= 1u << q;
        lane_count += std::popcount(mask_bits(a));
    }
    // The spread rule of walk(), over all the group's lanes.
    {
        float widen[2];
        for (int i = 0; i < 2; ++i)
            widen[i] = (slope_hi[i] - slope_lo[i]) * g.cell_size[k] * g.inv_cell_size[axes[i]];
        const float ahead = float(1 << macro.shift);
        if (!((1.0f + ahead * widen[0]) * (1.0f + ahead * widen[1]) <= float(kMaxCellsPerLane * lane_count)))
            return false;
    }
    first_cell = up ? first_cell - kCellMargin : first_cell + kCellMargin;
    const int res_k = g.res[k];
    const int s = first_cell > 0.0f ? (first_cell < float(res_k - 1) ? int(first_cell) : res_k - 1) : 0;
    const std::int32_t stride[3] = {1, g.res[0], g.res[0] * g.res[1]};
    const std::uint32_t* begin = grid.cell_begin.data();

    auto plane_t = [&](int q, int i) RAYPACK_INLINE_LAMBDA {
        const RayPacket<K>& ray = lanes.packet[q]->ray;
        return (F(g.plane(k, i)) - ray.org[k]) * ray.rdir[k];
    };
    // Each packet's bounds in the slice at hand (its lanes' segments), kept
    // to narrow a cell's tests down to the packets whose own rectangle holds
    // it; reduced to cells only in slices with a non-empty cell.
    F packet_lo[G][2], packet_hi[G][2];
    // Between planes at distances d0 and d1 from the point along k, the
    // lines of slopes [s_lo, s_hi] along axis axes[i] (the lines, not the
    // segments: a superset of every lane's cells).
    float slice_d0 = 0, slice_d1 = 0;
    auto point_span = [&](int i, float s_lo, float s_hi, float& lo, float& hi) RAYPACK_INLINE_LAMBDA {
        const float o = origin[axes[i]];
        const float c0 = slice_d0 * s_lo, c1 = slice_d0 * s_hi, c2 = slice_d1 * s_lo, c3 = slice_d1 * s_hi;
        const float a = o + std::min(std::min(c0, c1), std::min(c2, c3));
        const float b = o + std::max(std::max(c0, c1), std::max(c2, c3));
        const float slack = (std::fabs(o) + std::fabs(a) + std::fabs(b)) * kRelativeMargin;
        lo = a - slack, hi = b + slack;
    };
    // Per axis, packet by packet, the first and last cells of their
    // rectangles (as floats: whole numbers), compared with a cell's
    // coordinates W packets at a time.
    constexpr int W = kWidthCompiled<8> ? 8 : 4;
    static_assert(G % W == 0, "the packets' cell ranges are compared W at a time");
    using PF = vfloat<W>;
    alignas(32) float packet_first[2][G], packet_last[2][G];
    for (int q = 0; q < G; ++q)  // packets past the group: no cells
        packet_first[0][q] = packet_first[1][q] = 1.0f, packet_last[0][q] = packet_last[1][q] = 0.0f;
    // The packets whose rectangle holds cell `i` along axes[x].
    auto packets_holding = [&](int x, int i) RAYPACK_INLINE_LAMBDA {
        const PF c = PF(float(i));
        std::uint32_t bits = 0;
        for (int h = 0; h < G / W; ++h)
            bits |= mask_bits((PF::load_aligned(packet_first[x] + W * h) <= c) &
                              (c <= PF::load_aligned(packet_last[x] + W * h)))
                    << (W * h);
        return bits;
    };
    // cell_span() for every packet from one point, W at a time.
    auto packet_cell_spans_from_point = [&](int x) RAYPACK_INLINE_LAMBDA {
        const int a = axes[x];
        const PF o(origin[a]), d0(slice_d0), d1(slice_d1), rel_w(kRelativeMargin);
        const PF grid_lo(g.bounds.lo[a]), inv_cell(g.inv_cell_size[a]), margin(kCellMargin), zero(0.0f);
        const PF top(float(g.res[a] - 1));
        for (int h = 0; h < G / W; ++h) {
            const PF s_lo = PF::load_aligned(packet_slope_lo[x] + W * h);
            const PF s_hi = PF::load_aligned(packet_slope_hi[x] + W * h);
            const PF c0 = d0 * s_lo, c1 = d0 * s_hi, c2 = d1 * s_lo, c3 = d1 * s_hi;
            const PF lo_p = o + vmin(vmin(c0, c1), vmin(c2, c3));
            const PF hi_p = o + vmax(vmax(c0, c1), vmax(c2, c3));
            const PF slack = (vabs(o) + vabs(lo_p) + vabs(hi_p)) * rel_w;
            const PF lo_cell = (lo_p - slack - grid_lo) * inv_cell - margin;
            const PF hi_cell = (hi_p + slack - grid_lo) * inv_cell + margin;
            select(lo_cell > zero, select(lo_cell < top, round_down(lo_cell), top), zero)
                .store_aligned(packet_first[x] + W * h);
            select(hi_cell > zero, select(hi_cell < top, round_down(hi_cell), top), zero)
                .store_aligned(packet_last[x] + W * h);
        }
    };
    auto rectangle_from_point = [&](int i0, int i1, int first[2], int last[2], std::uint32_t& in_slice)
                                    RAYPACK_INLINE_LAMBDA {
        slice_d0 = g.plane(k, i0) - origin[k], slice_d1 = g.plane(k, i1) - origin[k];
        in_slice = walking;
        for (int i = 0; i < 2; ++i) {
            float lo, hi;
            point_span(i, slope_lo[i], slope_hi[i], lo, hi);
            cell_span(lo, hi, g.bounds.lo[axes[i]], g.inv_cell_size[axes[i]], g.res[axes[i]], first[i], last[i]);
        }
        return walking != 0;
    };
    // The union of the packets' rectangles between planes i0 and i1, and the
    // packets that have a lane there.
    auto rectangle = [&](int i0, int i1, int first[2], int last[2], std::uint32_t& in_slice) RAYPACK_INLINE_LAMBDA {
        if (one_point) return rectangle_from_point(i0, i1, first, last, in_slice);
        F lo[2] = {inf, inf}, hi[2] = {-inf, -inf};
        in_slice = 0;
        for (std::uint32_t bits = walking; bits; bits &= bits - 1) {
            const int q = std::countr_zero(bits);
            const RayPacket<K>& ray = lanes.packet[q]->ray;
            const F t0 = plane_t(q, i0), t1 = plane_t(q, i1);
            const F ta = vmax(vmin(t0, t1), lanes.entry[q]), tb = vmin(vmax(t0, t1), vmin(ray.tfar, exit[q]));
            const vmask<K> part = lanes.active[q] & (ta <= tb);
            if (none(part)) continue;
            in_slice |= 1u << q;
            for (int i = 0; i < 2; ++i) {
                const int a = axes[i];
                const F pa = ray.org[a] + ray.dir[a] * ta, pb = ray.org[a] + ray.dir[a] * tb;
                const F slack = (vabs(ray.org[a]) + vabs(pa) + vabs(pb)) * rel;
                packet_lo[q][i] = select(part, vmin(pa, pb) - slack, inf);
                packet_hi[q][i] = select(part, vmax(pa, pb) + slack, -inf);
                lo[i] = vmin(lo[i], packet_lo[q][i]);
                hi[i] = vmax(hi[i], packet_hi[q][i]);
            }
        }
        if (in_slice == 0) return false;
        for (int i = 0; i < 2; ++i)
            cell_span(lane_min<K>(lo[i]), lane_max<K>(hi[i]), g.bounds.lo[axes[i]], g.inv_cell_size[axes[i]],
                      g.res[axes[i]], first[i], last[i]);
        return true;
    };
    // Lanes stop at the end of a slice once their closest hit lies before
    // its far plane (each lane's own test, as walk()'s), but only packets
    // that may have such a lane run it: per packet, the cell coordinate
    // along k of its lanes' nearest end, less a cell (mirrored when going
    // down), compared with the plane's W packets at a time. The packets
    // whose lanes changed in the slice (closer hits) take theirs again first.
    alignas(32) float drop_at[G];
    std::uint32_t touched = 0;  // packets whose lanes changed since the last stop_before
    auto take_drop_at = [&](int q) RAYPACK_INLINE_LAMBDA {
        const RayPacket<K>& ray = lanes.packet[q]->ray;
        const vmask<K> a = lanes.active[q];
        const F end = vmin(ray.tfar, exit[q]);
        const F c = (ray.org[k] + ray.dir[k] * end - F(g.bounds.lo[k])) * F(g.inv_cell_size[k]);
        drop_at[q] = up ? lane_min<K>(select(a & (c == c), c, -inf)) - 1.0f
                        : -(lane_max<K>(select(a & (c == c), c, inf)) + 1.0f);
    };
    for (int q = 0; q < G; ++q) drop_at[q] = std::numeric_limits<float>::infinity();
    for (int q = 0; q < n; ++q) take_drop_at(q);
    bool narrowed = false;  // a packet's slopes narrowed since the group's were taken
    auto stop_before = [&](int i) RAYPACK_INLINE_LAMBDA {
        bool recount = touched != 0;
        for (std::uint32_t bits = touched & walking; bits; bits &= bits - 1) take_drop_at(std::countr_zero(bits));
        for (std::uint32_t bits = touched & ~walking; bits; bits &= bits - 1)
            drop_at[std::countr_zero(bits)] = std::numeric_limits<float>::infinity();
        touched = 0;
        const PF plane(up ? float(i) : -float(i));
        std::uint32_t due = 0;
        for (int h = 0; h < G / W; ++h) due |= mask_bits(PF::load_aligned(drop_at + W * h) <= plane) << (W * h);
        for (std::uint32_t bits = due & walking; bits; bits &= bits - 1) {
            const int q = std::countr_zero(bits);
            const F t_out = plane_t(q, i);
            const F end = vmin(lanes.packet[q]->ray.tfar, exit[q]);
            const vmask<K> before = lanes.active[q];
            lanes.active[q] = before & !(end + (vabs(end) + vabs(t_out)) * rel < t_out);
            const int c = std::popcount(mask_bits(lanes.active[q]));
            if (c == 0) {
                walking &= ~(1u << q), narrowed = one_point;
                drop_at[q] = std::numeric_limits<float>::infinity();
            } else if (c != std::popcount(mask_bits(before))) {
                if (one_point) packet_slopes(q), narrowed = true;
                take_drop_at(q);
            }
            recount = true;
        }
        if (recount) {
            lane_count = 0;
            for (std::uint32_t bits = walking; bits; bits &= bits - 1)
                lane_count += std::popcount(mask_bits(lanes.active[std::countr_zero(bits)]));
        }
        if (narrowed) {  // the group's slopes, for the rectangles from one point
            narrowed = false;
            slope_lo[0] = slope_lo[1] = std::numeric_limits<float>::infinity();
            slope_hi[0] = slope_hi[1] = -std::numeric_limits<float>::infinity();
            for (std::uint32_t bits = walking; bits; bits &= bits - 1) {
                const int q = std::countr_zero(bits);
                for (int x = 0; x < 2; ++x) {
                    slope_lo[x] = std::min(slope_lo[x], packet_slope_lo[x][q]);
                    slope_hi[x] = std::max(slope_hi[x], packet_slope_hi[x][q]);
                }
            }
        }
        return walking == 0;
    };

    std::uint32_t in_slice = 0;  // the packets with a lane in the slice of the last rectangle
    return walk_slices(
        grid, k, up, s,
        [&](int i0, int i1, int first[2], int last[2]) RAYPACK_INLINE_LAMBDA {
            return rectangle(i0, i1, first, last, in_slice);
        },
        [&](int slice, int cells) RAYPACK_INLINE_LAMBDA {
            if (cells <= kMaxCellsPerLane * lane_count) return false;
            for (std::uint32_t bits = walking; bits; bits &= bits - 1) {
                const int q = std::countr_zero(bits);
                lanes.entry[q] = vmax(lanes.entry[q], plane_t(q, up ? slice : slice + 1));
            }
            for (int q = 0; q < n; ++q)
                if (!((walking >> q) & 1u)) lanes.active[q] = lanes.active[q] & !lanes.active[q];
            return true;
        },
        [&](int slice, const int first[2], const int last[2]) RAYPACK_INLINE_LAMBDA {
            const std::uint32_t* row = begin + slice * stride[k] + first[1] * stride[v] + first[0] * stride[u];
            bool packet_cells = false;
            std::uint32_t in_row = 0;
            int row_of_packets = -1;
            for (int j = first[1]; j <= last[1]; ++j, row += stride[v]) {
                const std::uint32_t* cell = row;
                for (int i = first[0]; i <= last[0]; ++i, cell += stride[u]) {
                    if (cell[0] == cell[1]) continue;
                    if (!packet_cells) {
                        if (one_point) {
                            for (int x = 0; x < 2; ++x) packet_cell_spans_from_point(x);
                        } else {
                            for (std::uint32_t bits = in_slice; bits; bits &= bits - 1) {
                                const int q = std::countr_zero(bits);
                                for (int x = 0; x < 2; ++x) {
                                    int c0, c1;
                                    cell_span(lane_min<K>(packet_lo[q][x]), lane_max<K>(packet_hi[q][x]),
                                              g.bounds.lo[axes[x]], g.inv_cell_size[axes[x]], g.res[axes[x]], c0, c1);
                                    packet_first[x][q] = float(c0), packet_last[x][q] = float(c1);
                                }
                            }
                        }
                        packet_cells = true;
                        row_of_packets = -1;
                    }
                    if (row_of_packets != j) row_of_packets = j, in_row = in_slice & packets_holding(1, j);
                    const std::uint32_t here = in_row & packets_holding(0, i);
                    if (visit_cell(std::uint32_t(cell - begin), here, walking, touched)) return true;
                }
            }
            return false;
        },
        stop_before);
}

/// walk_group() testing each cell's primitives against the packets whose
/// rectangle holds the cell, each primitive once per packet. AnyHit: lanes that hit are added
/// to their packet's `occluded` and stop.
template <int K, int G, bool AnyHit>
bool trace_group(const Grid& grid, const PacketRecordIntersector<vfloat<K>>& isect, int k,
                 GroupLanes<K, G>& lanes) {
    GroupMailbox mailbox;
    const std::uint32_t* begin = grid.cell_begin.data();
    const std::uint32_t* refs = grid.refs.data();
    return walk_group<K, G>(grid, k, lanes,
                            [&](std::uint32_t c, std::uint32_t packets, std::uint32_t& walking,
                                std::uint32_t& changed) RAYPACK_INLINE_LAMBDA {
        for (std::uint32_t r = begin[c], r_end = begin[c + 1]; r < r_end; ++r) {
            const std::uint32_t prim = refs[r];
            std::uint32_t& tested = mailbox.tested(prim);
            const std::uint32_t todo = packets & walking & ~tested;
            tested |= todo;
            for (std::uint32_t bits = todo; bits; bits &= bits - 1) {
                const int q = std::countr_zero(bits);
                LoadedPacket<K>& p = *lanes.packet[q];
                const vmask<K> m = isect.intersect(lanes.active[q], p.ray, p.hit, prim);
                if (!any(m)) continue;
                changed |= 1u << q;
                if constexpr (AnyHit) {
                    p.occluded = p.occluded | m;
                    lanes.active[q] = lanes.active[q] & !m;
                    if (none(lanes.active[q])) {
                        walking &= ~(1u << q);
                        if (walking == 0) return true;
                    }
                }
            }
        }
        return false;
    });
}

}  // namespace raypack::coherent_grid
