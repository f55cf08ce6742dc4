#include "accel/kdtree/kdtree_packet.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "accel/group_box_culling.h"
#include "accel/kdtree/kdtree_ray_interval.h"
#include "accel/outside_prims.h"
#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "accel/packet_mailbox.h"
#include "accel/packet_ties.h"
#include "kernels/ray_packet.h"

namespace raypack {
namespace {

template <class F>
RAYPACK_INLINE F select_if(bool c, const F& a, const F& b) {
    return c ? a : b;
}

/// The lanes of `m` get back their hit from `before`.
template <int K>
void restore_lanes(const vmask<K>& m, const HitPacket<K>& before, HitPacket<K>& hit) {
    hit.t = select(m, before.t, hit.t);
    hit.u = select(m, before.u, hit.u);
    hit.v = select(m, before.v, hit.v);
    for (std::uint32_t bits = mask_bits(m); bits; bits &= bits - 1) {
        const int l = std::countr_zero(bits);
        hit.prim[l] = before.prim[l];
    }
}

/// Whether the lanes `bits` share one sign per axis of their reciprocal
/// directions.
template <int K>
RAYPACK_INLINE bool one_octant(const Vec3<vfloat<K>>& rdir, std::uint32_t bits) {
    for (int a = 0; a < 3; ++a) {
        const std::uint32_t positive = mask_bits(rdir[a] >= vfloat<K>(0.0f)) & bits;
        if (positive != 0 && positive != bits) return false;
    }
    return true;
}

/// Whether a packet may start a group (trace_group): its rays leave one
/// point and share one direction octant.
template <int K>
RAYPACK_INLINE bool may_lead_group(const LoadedPacket<K>& p) {
    const std::uint32_t bits = mask_bits(p.valid);
    return bits && one_octant<K>(p.ray.rdir, bits) && one_origin<K>(p);
}

/// The primitives of leaf `node` against the lanes `active` (closest hits,
/// or occlusion added to `occluded`), each primitive only on the lanes the
/// packet's mailbox has not settled: the leaf step of both walks below.
template <int K, bool AnyHit, bool Culled = false>
RAYPACK_INLINE void test_leaf(const KdTree& tree, const PacketPrimitiveIntersector<vfloat<K>>& isect,
                              const KdNode& node, RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> active,
                              vmask<K>& occluded, PacketMailbox& mailbox, const std::uint32_t* may_hit = nullptr,
                              std::uint32_t packet_bit = 0) {
    using F = vfloat<K>;
    using M = vmask<K>;
    const F inf(std::numeric_limits<float>::infinity());
    const bool double_ties = isect.kernels.precision == Precision::Double;
    const std::uint32_t count = node.prim_count();
    const std::uint32_t* prims = tree.leaf_prims(node);
    for (std::uint32_t k = 0; k < count; ++k) {
        if constexpr (Culled)
            if (!(may_hit[k] & packet_bit)) continue;
        // A test again only finds its own hit: ties go to the lowest primitive.
        std::uint32_t& settled = mailbox.settled(prims[k]);
        if (!(mask_bits(active) & ~settled)) continue;
        settled |= mask_bits(active);
        if constexpr (AnyHit) {
            const M m = isect.intersect(active, ray, hit, prims[k]);
            occluded = occluded | m;
            active = active & !m;
            if (none(active)) break;
        } else if (double_ties) {  // see kd_tie_tfar()
            const HitPacket<K> before = hit;
            const F tfar = ray.tfar;
            ray.tfar = select(active & (before.t < inf), kd_tie_tfar(tfar), tfar);
            const M m = isect.intersect(active, ray, hit, prims[k]);
            const M farther = m & (hit.t > before.t);
            if (any(farther)) restore_lanes<K>(farther, before, hit);
            ray.tfar = select(m & !farther, hit.t, tfar);
            const M tie = m & !farther & (hit.t == before.t);
            if (any(tie)) [[unlikely]]
                keep_lowest_on_ties<K>(tie, before, hit, prims[k]);
        } else {
            // Equal t: the lowest primitive number wins, as in the single-ray
            // path (checked before the hit is recorded: no copy of the hits).
            intersect_keeping_lowest<K>(isect, active, ray, hit, prims[k]);
        }
    }
}

// The single-ray traversal of kdtree_accel.cpp lane by lane: the same
// widened planes, so every lane visits at least the leaves its single ray
// would, and the same kernels, so the hits are bit for bit the same. A lane
// is active in a node while tmin <= min(tmax, tfar). With robust slabs, at
// a leaf every lane still traced tests the primitives, also those that do
// not reach it: a hit there is its ray's own within [tnear, tfar], and none
// is closer than the one its single ray finds (that hit point lies in a
// leaf the single walk visits, which holds the primitive too), while the
// mailbox then settles each primitive for all lanes at once, so that one
// met again in a later leaf is not tested again (shadow rays 1.04-1.10x,
// diffuse 1.02-1.06x against the lanes that reach the leaf). Plain slabs
// can lose a leaf that holds a single ray's closest hit, so there only the
// lanes that reach the leaf test it, as their single rays do.
// SameSigns: every lane in the root box has the same direction signs (all
// camera packets but those straddling the image's centre lines), so the
// near child is the same for all lanes (Wald's thesis, 2004, 7.1): each
// inner node costs two compares and no per-lane choice of child intervals.
// The nodes visited and the hits are those of the general walk.
template <int K, bool AnyHit, SlabMethod Slabs, bool SameSigns>
void trace_packet(const KdTree& tree, const PacketPrimitiveIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
                  HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded, vmask<K> in_box, vfloat<K> tmin,
                  vfloat<K> tmax) {
    using F = vfloat<K>;
    using M = vmask<K>;
    const F inf(std::numeric_limits<float>::infinity());
    // Inactive lanes get an empty interval, which stays empty in every child.
    tmin = select(in_box, tmin, inf);
    tmax = select(in_box, tmax, -inf);
    constexpr bool plain = Slabs == SlabMethod::Plain;
    const F margin(plain ? 0.0f : tree.margin);
    // What a split plane along each axis needs, indexed by the node's axis
    // (Vec3's operator[] compiles to a chain of compares and blends).
    struct AxisLanes {
        F org, rdir, org_rdir, slack;
    };
    AxisLanes axes[3];
    for (int a = 0; a < 3; ++a)
        axes[a] = {ray.org[a], ray.rdir[a], ray.org[a] * ray.rdir[a], margin * vabs(ray.rdir[a])};
    const M positive[3] = {ray.rdir.x >= F(0.0f), ray.rdir.y >= F(0.0f), ray.rdir.z >= F(0.0f)};
    // Bit a: the lanes' below child comes first along axis a (SameSigns).
    const std::uint32_t lanes = mask_bits(in_box);
    const std::uint32_t below_first_axes = std::uint32_t((mask_bits(positive[0]) & lanes) != 0) |
                                           std::uint32_t((mask_bits(positive[1]) & lanes) != 0) << 1 |
                                           std::uint32_t((mask_bits(positive[2]) & lanes) != 0) << 2;
    const KdNode* nodes = tree.nodes.data();
    // The far children still to visit, with their intervals: lanes stored
    // one by one (a struct of vectors made GCC copy them through scalar
    // registers and keep tmax in memory).
    alignas(64) float stack_tmin[kKdMaxDepth + 1][K], stack_tmax[kKdMaxDepth + 1][K];
    std::uint32_t stack_node[kKdMaxDepth + 1];
    const auto push = [&](int sp, const F& lo, const F& hi, std::uint32_t node) RAYPACK_INLINE_LAMBDA {
        lo.store_aligned(stack_tmin[sp]);
        hi.store_aligned(stack_tmax[sp]);
        stack_node[sp] = node;
    };
    int sp = 0;
    std::uint32_t current = 0;
    PacketMailbox mailbox;
    // Enters `node` with the lanes that reach it before their closest hit so
    // far (all there is to a pop); false if there are none.
    const auto resume = [&](const F& lo, const F& hi_before_hits, std::uint32_t node) RAYPACK_INLINE_LAMBDA {
        const F hi = vmin(hi_before_hits, ray.tfar);
        M live = lo <= hi;
        if constexpr (AnyHit) live = live & valid;
        if (none(live)) return false;
        current = node;
        tmin = select(live, lo, inf);
        tmax = select(live, hi, -inf);
        return true;
    };
    for (;;) {
        const KdNode node = nodes[current];
        if (!node.is_leaf()) {
            const int a = node.axis();
            const AxisLanes& axis = axes[a];
            // The split broadcast straight from the node (through a scalar
            // register it added two steps to every node's latency).
            float split_pos;
            std::memcpy(&split_pos, &nodes[current].word, sizeof split_pos);
            const F split(split_pos);
            const F t_split = plane_distance<Slabs>(split, axis.org, axis.rdir, axis.org_rdir);
            const F near_end = vmin(tmax, plain ? t_split : t_split + axis.slack);
            const F far_start = vmax(tmin, plain ? t_split : t_split - axis.slack);
            if constexpr (SameSigns) {
                const bool visit_near = any(tmin <= near_end), visit_far = any(far_start <= tmax);
                const bool below_first = (below_first_axes >> a) & 1u;
                const std::uint32_t below = node.below_child(current), above = node.above_child();
                const std::uint32_t near = below_first ? below : above;
                const std::uint32_t far = below_first ? above : below;
                // Child 0 is empty space: not visited (see KdNode).
                if (visit_near && near) {
                    if (visit_far && far) push(sp++, far_start, tmax, far);
                    current = near, tmax = near_end;
                    continue;
                }
                if (!visit_near && far) {
                    current = far, tmin = far_start;
                    continue;
                }
                // Past empty space the far side is entered as if popped.
                if (visit_far && far && resume(far_start, tmax, far)) continue;
            } else {
                // Per lane, below is the near side where the direction is positive.
                const M pos = positive[a];
                const F below_lo = select(pos, tmin, far_start), below_hi = select(pos, near_end, tmax);
                const F above_lo = select(pos, far_start, tmin), above_hi = select(pos, tmax, near_end);
                const bool any_below = any(below_lo <= below_hi), any_above = any(above_lo <= above_hi);
                const std::uint32_t below = node.below_child(current), above = node.above_child();
                // Front to back for the first active lane; the packet takes
                // the above side when it finds no lane below.
                const std::uint32_t first = std::countr_zero(mask_bits(tmin <= tmax));
                const bool below_first = any_below && (!any_above || ((mask_bits(pos) >> first) & 1u));
                const bool visit_second = any_below && any_above;
                const std::uint32_t first_child = below_first ? below : above;
                const std::uint32_t second_child = below_first ? above : below;
                const F first_lo = select_if(below_first, below_lo, above_lo);
                const F first_hi = select_if(below_first, below_hi, above_hi);
                const F second_lo = select_if(below_first, above_lo, below_lo);
                const F second_hi = select_if(below_first, above_hi, below_hi);
                if (first_child) {
                    if (visit_second && second_child) push(sp++, second_lo, second_hi, second_child);
                    current = first_child, tmin = first_lo, tmax = first_hi;
                    continue;
                }
                if (visit_second && second_child && resume(second_lo, second_hi, second_child)) continue;
            }
        } else {
            // Robust slabs: every lane still traced, not only those that
            // reach the leaf (see above).
            const M testing = plain ? tmin <= tmax : AnyHit ? in_box & valid : in_box;
            test_leaf<K, AnyHit>(tree, isect, nodes[current], ray, hit, testing, occluded, mailbox);
            if constexpr (AnyHit) {
                valid = valid & !occluded;
                if (none(valid)) return;
            }
        }
        // Pop the next node some lane reaches before its closest hit so far.
        for (;;) {
            if (sp == 0) return;
            --sp;
            if (resume(F::load_aligned(stack_tmin[sp]), F::load_aligned(stack_tmax[sp]), stack_node[sp])) break;
        }
    }
}

#if defined(__AVX2__)
/// A leaf that this many packets of a group reach, and of at most
/// kMaxCulledPrims primitives, first tests its primitives' boxes against
/// each packet's bounds, and each packet tests only those it may meet
/// (as the BVH's groups do, wide_group_traversal.h). Fewer packets do not
/// repay the boxes (callgrind, camera rays 1024 x 1024: culling at every
/// leaf cost balls 2% and gears 1% more instructions, saved teapot 9%; from
/// 8 packets on, teapot -10%, the others within 2%).
inline constexpr int kMinPacketsToCull = 8;
inline constexpr std::uint32_t kMaxCulledPrims = 32;

/// Up to G packets of rays from one point, in one direction octant, walk
/// the tree together ("large packets": Reshetov, Soupikov & Hurley,
/// "Multi-Level Ray Tracing Algorithm", SIGGRAPH 2005; Wald's thesis 2004).
/// Each packet stands for its rays by intervals, per axis, of their
/// reciprocal directions, from which a split's crossing is bounded for all
/// of them at once; the walk is the single-ray walk on one interval [enter,
/// leave] per packet, the packets in SIMD lanes, so an inner node costs a
/// few vector operations for all the group's rays instead of a step per
/// packet. Rounding is monotone, so the corner products (split - o) * r
/// bound every lane's own t_split and the largest |r| its slack (as
/// trace_packet computes them, robust slabs): a packet enters every node
/// one of its lanes would. At a leaf each packet that reaches it tests the
/// primitives with all its lanes still traced, as trace_packet does (but
/// those whose widened boxes its bounds miss, where kMinPacketsToCull
/// packets reach the leaf), so every lane tests at least the primitives its
/// single ray would find and keeps the same closest hit (ties go to the
/// lowest primitive in both). Clipping each packet's lanes to the leaf's
/// cell first cost the clip and left the lanes outside it unsettled in the
/// mailbox, to test the primitive again in the next leaf: camera rays
/// 1.06-1.19x faster without it (docs/structures.md).
/// Origins must coincide: with origins spread over a patch (shadow rays),
/// rays nearly parallel to a split bound nothing. Robust slabs and float
/// precision only; false (nothing traced) if the packets do not share one
/// origin and octant or a lane's origin or reciprocal is not finite.
template <int K, int G, bool AnyHit>
bool trace_group(const KdTree& tree, const PacketPrimitiveIntersector<vfloat<K>>& isect, LoadedPacket<K>* p,
                 int count) {
    using F = vfloat<K>;
    using M = vmask<K>;
    using PF = vfloat<8>;  // one lane per packet, G / 8 vectors of them
    constexpr int H = G / 8;
    static_assert(G % 8 == 0 && G <= 32);
    const float inf = std::numeric_limits<float>::infinity();
    const F finf(inf), zero(0.0f);
    M lanes[G];  // per packet: the lanes still traced
    alignas(32) float org[3][G], r_lo[3][G], r_hi[3][G], r_abs[3][G], t_in[G], t_out[G], t_far[G];
    std::uint32_t up = 0, down = 0, live = 0;
    F non_finite = zero;
    for (int q = 0; q < count; ++q) {
        const RayPacket<K>& ray = p[q].ray;
        F t0, t1;
        const M in = ray_box_interval<F>(p[q].valid, ray.org, ray.rdir, ray.tnear, ray.tfar, tree.bounds, tree.margin,
                                        t0, t1);
        lanes[q] = in;
        const std::uint32_t bits = mask_bits(in);
        if (bits == 0) continue;
        live |= 1u << q;
        const int first = std::countr_zero(bits);
        for (int a = 0; a < 3; ++a) {
            const std::uint32_t pos = mask_bits(ray.rdir[a] >= zero) & bits;
            up |= pos != 0 ? 1u << a : 0u;
            down |= pos != bits ? 1u << a : 0u;
            const F o = ray.org[a], r = ray.rdir[a];
            non_finite = non_finite + select(in, (o - o) + (r - r), zero);
            // Bounds by intervals are tight only for rays from one point:
            // packets whose origins spread walk alone (shadow rays from a
            // patch, nearly parallel to a split, would bound nothing).
            org[a][q] = lane(o, first);
            if (mask_bits(o != F(org[a][q])) & bits) return false;
            r_lo[a][q] = lane_min<K>(select(in, r, finf));
            r_hi[a][q] = lane_max<K>(select(in, r, -finf));
            r_abs[a][q] = std::max(std::fabs(r_lo[a][q]), std::fabs(r_hi[a][q]));
        }
        t_in[q] = lane_min<K>(select(in, t0, finf));
        t_out[q] = lane_max<K>(select(in, t1, -finf));
        t_far[q] = lane_max<K>(select(in, ray.tfar, -finf));
    }
    if ((up & down) != 0 || any(non_finite != non_finite)) return false;
    if (live == 0) return true;
    for (int q = 0; q < G; ++q)  // packets without a lane in the box, or past the group: empty intervals
        if (!((live >> q) & 1u)) {
            for (int a = 0; a < 3; ++a) org[a][q] = r_lo[a][q] = r_hi[a][q] = r_abs[a][q] = 0.0f;
            t_in[q] = inf, t_out[q] = -inf, t_far[q] = -inf;
        }
    float g_lo[3], g_hi[3];  // the packets' origins, all of them (culling_box_pad)
    for (int a = 0; a < 3; ++a) {
        g_lo[a] = inf, g_hi[a] = -inf;
        for (std::uint32_t b = live; b != 0; b &= b - 1) {
            const int q = std::countr_zero(b);
            g_lo[a] = std::min(g_lo[a], org[a][q]), g_hi[a] = std::max(g_hi[a], org[a][q]);
        }
    }
    PF tfar[H], enter[H], leave[H];
    for (int h = 0; h < H; ++h) {
        tfar[h] = PF::load_aligned(t_far + 8 * h);
        enter[h] = PF::load_aligned(t_in + 8 * h);
        leave[h] = PF::load_aligned(t_out + 8 * h);
    }
    struct UnsetMailbox : PacketMailbox {
        UnsetMailbox() : PacketMailbox(Unset{}) {}
    };
    UnsetMailbox mailbox[G];
    for (int q = 0; q < count; ++q) mailbox[q].clear();
    // The far children still to visit, and the packets' intervals in them.
    struct Pending {
        std::uint32_t node, packets;
    };
    alignas(32) float stack_enter[kKdMaxDepth + 1][G], stack_leave[kKdMaxDepth + 1][G];
    Pending stack[kKdMaxDepth + 1];
    int sp = 0;
    const KdNode* nodes = tree.nodes.data();
    const PF margin(tree.margin);
    std::uint32_t current = 0, packets = live;
    // Primitive boxes are widened for the whole tree's reach: the leaf's own
    // cell, kept on the stack for it, was no faster (0.99-1.03x).
    const float pad = culling_box_pad(tree.bounds, g_lo, g_hi);
    for (;;) {
        const KdNode& node = nodes[current];
        if (!node.is_leaf()) {
            const int a = node.axis();
            float split_pos;
            std::memcpy(&split_pos, &node.word, sizeof split_pos);
            const PF split(split_pos);
            PF near_hi[H], far_lo[H];
            std::uint32_t near_packets = 0, far_packets = 0;
            for (int h = 0; h < H; ++h) {
                const PF d = split - PF::load_aligned(org[a] + 8 * h);
                const PF rl = PF::load_aligned(r_lo[a] + 8 * h), rh = PF::load_aligned(r_hi[a] + 8 * h);
                const PF c0 = d * rl, c1 = d * rh;
                const PF slack = margin * PF::load_aligned(r_abs[a] + 8 * h);
                // Whichever way the rays go, the near side ends at t_split +
                // slack and the far side starts at t_split - slack.
                const PF near_end = vmax(c0, c1) + slack;
                const PF far_start = vmin(c0, c1) - slack;
                near_hi[h] = vmin(leave[h], near_end);
                far_lo[h] = vmax(enter[h], far_start);
                near_packets |= mask_bits((enter[h] <= near_hi[h]) & (enter[h] <= tfar[h])) << (8 * h);
                far_packets |= mask_bits((far_lo[h] <= leave[h]) & (far_lo[h] <= tfar[h])) << (8 * h);
            }
            near_packets &= packets;
            far_packets &= packets;
            const bool below_first = (up >> a) & 1u;
            const std::uint32_t below = node.below_child(current), above = node.above_child();
            const std::uint32_t near = below_first ? below : above, far = below_first ? above : below;
            if (near && near_packets) {
                if (far && far_packets) {
                    Pending& e = stack[sp];
                    e.node = far, e.packets = far_packets;
                    for (int h = 0; h < H; ++h) {
                        far_lo[h].store_aligned(stack_enter[sp] + 8 * h);
                        leave[h].store_aligned(stack_leave[sp] + 8 * h);
                    }
                    ++sp;
                }
                for (int h = 0; h < H; ++h) leave[h] = near_hi[h];
                current = near, packets = near_packets;
                continue;
            }
            if (far && far_packets) {
                for (int h = 0; h < H; ++h) enter[h] = far_lo[h];
                current = far, packets = far_packets;
                continue;
            }
        } else if (node.prim_count() != 0) {
            alignas(32) float t_far_now[G];
            for (int h = 0; h < H; ++h) tfar[h].store_aligned(t_far_now + 8 * h);
            // The packets each primitive's box may meet, per primitive.
            std::uint32_t may_hit[kMaxCulledPrims];
            const std::uint32_t n_prims = node.prim_count();
            const bool culled = n_prims <= kMaxCulledPrims && std::popcount(packets) >= kMinPacketsToCull;
            if (culled) {
                const std::uint32_t* prims = tree.leaf_prims(node);
                for (std::uint32_t k = 0; k < n_prims; ++k)
                    may_hit[k] = packets_meeting_box<G>(org, r_lo, r_hi, up, primitive_bounds(*isect.scene, prims[k]),
                                                        pad, tfar);
            }
            for (std::uint32_t b = packets; b != 0; b &= b - 1) {
                const int q = std::countr_zero(b);
                RayPacket<K>& ray = p[q].ray;
                if (culled)
                    test_leaf<K, AnyHit, true>(tree, isect, node, ray, p[q].hit, lanes[q], p[q].occluded, mailbox[q],
                                               may_hit, 1u << q);
                else
                    test_leaf<K, AnyHit>(tree, isect, node, ray, p[q].hit, lanes[q], p[q].occluded, mailbox[q]);
                if constexpr (AnyHit) {
                    lanes[q] = lanes[q] & !p[q].occluded;
                    if (none(lanes[q])) live &= ~(1u << q), t_far_now[q] = -inf;
                } else {
                    t_far_now[q] = lane_max<K>(select(lanes[q], ray.tfar, -finf));
                }
            }
            if (live == 0) return true;
            for (int h = 0; h < H; ++h) tfar[h] = PF::load_aligned(t_far_now + 8 * h);
        }
        // Pop the next node some packet may reach before its closest hits.
        for (;;) {
            if (sp == 0) return true;
            --sp;
            std::uint32_t reach = 0;
            for (int h = 0; h < H; ++h)
                reach |= mask_bits(PF::load_aligned(stack_enter[sp] + 8 * h) <= tfar[h]) << (8 * h);
            packets = stack[sp].packets & live & reach;
            if (packets) {
                current = stack[sp].node;
                for (int h = 0; h < H; ++h) {
                    enter[h] = PF::load_aligned(stack_enter[sp] + 8 * h);
                    leave[h] = PF::load_aligned(stack_leave[sp] + 8 * h);
                }
                break;
            }
        }
    }
}

#endif  // __AVX2__

}  // namespace

template <int K, bool AnyHit>
void kdtree_trace_packets(const KdTree& tree, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                          std::span<Hitf> hits, bool groups) {
    using F = vfloat<K>;
    const PacketPrimitiveIntersector<F> isect{&scene, kernels};
    // The slab form is chosen once for all packets, rdir once per packet.
    with_slab_form(kernels.slabs, [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
        // The primitives outside the leaves first: their hits shorten the walk.
        const auto walk_one = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
            if (tree.empty()) return;
            vfloat<K> tmin, tmax;
            const vmask<K> in_box = ray_box_interval<vfloat<K>, Slabs>(valid, ray.org, ray.rdir, ray.tnear, ray.tfar,
                                                                      tree.bounds, tree.margin, tmin, tmax);
            const std::uint32_t lanes = mask_bits(in_box);
            if (!lanes) return;
            if (one_octant<K>(ray.rdir, lanes))
                trace_packet<K, AnyHit, Slabs, true>(tree, isect, ray, hit, valid, occluded, in_box, tmin, tmax);
            else
                trace_packet<K, AnyHit, Slabs, false>(tree, isect, ray, hit, valid, occluded, in_box, tmin, tmax);
        };
        const auto trace_one = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
            intersect_outside<K, AnyHit>(tree.outside, isect, ray, hit, valid, occluded);
            walk_one(ray, hit, valid, occluded);
        };
        // Rays from one point (pinhole camera rays) walk in groups; the
        // walk's bounds need robust slabs and float tests (trace_group).
#if defined(__AVX2__)
        if constexpr (Slabs == SlabMethod::Robust) {
            if (groups && !tree.empty() && kernels.precision == Precision::Float) {
                constexpr int G = kKdGroupPackets;
                trace_in_groups_or_alone<K, G, AnyHit>(
                    rays, hits, kernels.rcp, [](const LoadedPacket<K>& p) { return may_lead_group<K>(p); }, trace_one,
                    [&](LoadedPacket<K>* p, int count) {
                        for (int q = 0; q < count; ++q)
                            intersect_outside<K, AnyHit>(tree.outside, isect, p[q].ray, p[q].hit, p[q].valid,
                                                         p[q].occluded);
                        if (trace_group<K, G, AnyHit>(tree, isect, p, count)) return true;
                        for (int q = 0; q < count; ++q) walk_one(p[q].ray, p[q].hit, p[q].valid, p[q].occluded);
                        return true;
                    });
                return;
            }
        }
#else
        (void)groups;
#endif
        trace_in_packets<K, AnyHit>(rays, hits, kernels.rcp, trace_one);
    });
}

#if defined(__SSE4_2__)
template void kdtree_trace_packets<4, false>(const KdTree&, const Scene&, KernelChoice,
                                                std::span<const Rayf>, std::span<Hitf>, bool);
template void kdtree_trace_packets<4, true>(const KdTree&, const Scene&, KernelChoice,
                                                std::span<const Rayf>, std::span<Hitf>, bool);
#endif
#if defined(__AVX2__)
template void kdtree_trace_packets<8, false>(const KdTree&, const Scene&, KernelChoice,
                                                std::span<const Rayf>, std::span<Hitf>, bool);
template void kdtree_trace_packets<8, true>(const KdTree&, const Scene&, KernelChoice,
                                                std::span<const Rayf>, std::span<Hitf>, bool);
#endif
#if defined(__AVX512BW__)
template void kdtree_trace_packets<16, false>(const KdTree&, const Scene&, KernelChoice,
                                                std::span<const Rayf>, std::span<Hitf>, bool);
template void kdtree_trace_packets<16, true>(const KdTree&, const Scene&, KernelChoice,
                                                std::span<const Rayf>, std::span<Hitf>, bool);
#endif

}  // namespace raypack
