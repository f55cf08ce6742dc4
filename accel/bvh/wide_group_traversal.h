#pragma once
// Groups of packets sharing one walk of the wide BVH ("large packets": Wald,
// Boulos, Shirley, "Ray Tracing Deformable Scenes Using Dynamic Bounding
// Volume Hierarchies", ACM TOG 2007; the interval test after Boulos et al.,
// "Geometric and Arithmetic Culling Methods for Entire Ray Packets", 2006),
// included only by the .cpp files that instantiate the packet traversal.
//
// G packets of K rays walk the tree once. At an inner node the group's rays
// as intervals (origins, reciprocals, tnear and tfar over every lane) reject
// at once the children no ray can meet, for all N children in one SIMD test;
// a child that survives is tested packet by packet from the group's first
// active packet, and entered by the first packet some lane of which meets it
// and every active packet after it ("first active": the packets before it
// are known to miss it, those after it are not tested until they must be).
// At a leaf the group first drops the primitives whose (slightly widened)
// boxes none of its rays can meet, with the same interval test; then each
// of those packets tests the leaf's box and the remaining primitives, with
// the kernels and the per-lane tests of the single-packet walk
// (wide_packet_traversal.h), so every (ray, primitive) pair tested gives
// the same answer; as there, only which of two nearly coincident hits is
// kept may differ from the single ray.
//
// The interval test is exact in floating point: a lane's near distance is
// round(round(plane - o) * r), and rounding is monotone, so the smallest of
// the four products of the extreme (plane - o) and r bounds every lane's
// from below, and likewise the largest far distance from above. It needs
// finite origins and reciprocals and one direction sign per axis over the
// group, and the group's origins must lie close together
// (max_origin_spread); other groups trace packet by packet.
#include <array>
#include <bit>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "accel/bvh/wide_packet_traversal.h"

namespace raypack::wide_packet_detail {

/// The group's rays as intervals, per axis: origins [o_lo, o_hi], near and
/// far reciprocals [r_lo, r_hi] and [f_lo, f_hi], and the row of the node's
/// near plane (0..2: lo, 3..5: hi).
struct GroupIntervals {
    float o_lo[3], o_hi[3], r_lo[3], r_hi[3], f_lo[3], f_hi[3];
    int near_row[3];
    float tnear_lo;
};

/// Whether the valid lanes of `count` packets share one direction sign per
/// axis (a lane's sign is its reciprocal's, as the node test picks planes).
template <int K>
RAYPACK_INLINE bool one_octant(const LoadedPacket<K>* p, int count) {
    using F = vfloat<K>;
    const F zero(0.0f);
    std::uint32_t neg_any = 0, neg_all = 7, valid_any = 0;
    for (int q = 0; q < count; ++q) {
        const std::uint32_t v = mask_bits(p[q].valid);
        if (v == 0) continue;
        valid_any = 1;
        const std::uint32_t nx = mask_bits(p[q].ray.rdir.x < zero) & v, ny = mask_bits(p[q].ray.rdir.y < zero) & v,
                            nz = mask_bits(p[q].ray.rdir.z < zero) & v;
        neg_any |= (nx != 0 ? 1u : 0u) | (ny != 0 ? 2u : 0u) | (nz != 0 ? 4u : 0u);
        neg_all &= (nx == v ? 1u : 0u) | (ny == v ? 2u : 0u) | (nz == v ? 4u : 0u);
    }
    return valid_any != 0 && neg_any == neg_all;
}

/// The intervals of `count` packets' valid lanes (one_octant holds); false
/// if the test does not apply (a NaN or infinite origin or reciprocal). A
/// lane with a NaN tnear meets no box and is left out.
template <int K>
inline bool group_intervals(const PacketNodeRay<K>* nr, const LoadedPacket<K>* p, int count, GroupIntervals& g) {
    using F = vfloat<K>;
    const F inf(std::numeric_limits<float>::infinity()), zero(0.0f);
    F o_lo[3] = {inf, inf, inf}, o_hi[3] = {-inf, -inf, -inf}, r_lo[3] = {inf, inf, inf}, r_hi[3] = {-inf, -inf, -inf};
    F f_lo[3] = {inf, inf, inf}, f_hi[3] = {-inf, -inf, -inf}, tnear_lo = inf;
    F non_finite = zero;  // x - x is NaN for NaN and +-inf, 0 otherwise; sums keep the NaN
    for (int q = 0; q < count; ++q) {
        const vmask<K> v = p[q].valid;
        for (int a = 0; a < 3; ++a) {
            const F o = nr[q].org[a], r = nr[q].rdir[a], f = nr[q].rdir_far[a];
            non_finite = non_finite + select(v, (o - o) + (r - r) + (f - f), zero);
            o_lo[a] = vmin(o_lo[a], select(v, o, inf));
            o_hi[a] = vmax(o_hi[a], select(v, o, -inf));
            r_lo[a] = vmin(r_lo[a], select(v, r, inf));
            r_hi[a] = vmax(r_hi[a], select(v, r, -inf));
            f_lo[a] = vmin(f_lo[a], select(v, f, inf));
            f_hi[a] = vmax(f_hi[a], select(v, f, -inf));
        }
        tnear_lo = vmin(tnear_lo, select(v, nr[q].tnear, inf));
    }
    if (any(non_finite != non_finite)) return false;
    for (int a = 0; a < 3; ++a) {
        g.o_lo[a] = lane_min<K>(o_lo[a]);
        g.o_hi[a] = lane_max<K>(o_hi[a]);
        g.r_lo[a] = lane_min<K>(r_lo[a]);
        g.r_hi[a] = lane_max<K>(r_hi[a]);
        g.f_lo[a] = lane_min<K>(f_lo[a]);
        g.f_hi[a] = lane_max<K>(f_hi[a]);
        g.near_row[a] = g.r_hi[a] < 0.0f ? a + 3 : a;
    }
    g.tnear_lo = lane_min<K>(tnear_lo);
    return true;
}

/// The widest spread of origins a group may have: a sixteenth of the
/// scene's largest extent. Shadow rays toward a light from points all over
/// the scene (a Whitted render's reflected levels) share an octant but no
/// beam, and walking them together cost more than it saved (callgrind, a
/// gears render at 512 x 512: 2.59 G instructions with groups of any
/// spread, 2.54 G alone, 2.50 G with this limit; 1/32: 2.52 G).
template <int N, int M>
float max_origin_spread(const WideBvh<N, M>& bvh) {
    Box3f scene;  // empty
    const WideNode<N>& root = bvh.nodes[0];
    for (int i = 0; i < N; ++i)
        if (root.child[i] != wide_child::kEmpty) scene.extend(root.box(i));
    const Vec3f e = scene.extent();
    return std::max({e.x, e.y, e.z}) / 16.0f;
}

/// The largest extent of the group's origins.
RAYPACK_INLINE float origin_spread(const GroupIntervals& g) {
    return vmax(vmax(g.o_hi[0] - g.o_lo[0], g.o_hi[1] - g.o_lo[1]), g.o_hi[2] - g.o_lo[2]);
}

/// Which of W boxes (lo, hi per axis) some ray of the group may meet
/// before `tfar_hi`, as bits; `entry` gets each box's lower bound on the
/// entry distance. An empty box (lo = +inf, hi = -inf) gives enter = +inf
/// or NaN: not <=.
template <int W>
RAYPACK_INLINE std::uint32_t group_box_candidates(const vfloat<W> (&lo)[3], const vfloat<W> (&hi)[3],
                                                  const GroupIntervals& g, float tfar_hi, vfloat<W>& entry) {
    using V = vfloat<W>;
    V enter(g.tnear_lo), leave(tfar_hi);
    for (int a = 0; a < 3; ++a) {
        const bool near_is_lo = g.near_row[a] < 3;
        const V near_plane = near_is_lo ? lo[a] : hi[a], far_plane = near_is_lo ? hi[a] : lo[a];
        // plane - o is largest at o_lo and smallest at o_hi.
        const V n0 = near_plane - V(g.o_hi[a]), n1 = near_plane - V(g.o_lo[a]);
        const V f0 = far_plane - V(g.o_hi[a]), f1 = far_plane - V(g.o_lo[a]);
        const V r0(g.r_lo[a]), r1(g.r_hi[a]), s0(g.f_lo[a]), s1(g.f_hi[a]);
        const V near_lo = vmin(vmin(n0 * r0, n0 * r1), vmin(n1 * r0, n1 * r1));
        const V far_hi = vmax(vmax(f0 * s0, f0 * s1), vmax(f1 * s0, f1 * s1));
        enter = vmax(enter, near_lo);
        leave = vmin(leave, far_hi);
    }
    entry = enter;
    return mask_bits(enter <= leave);
}

/// Children of `node` some ray of the group may meet before `tfar_hi` (the
/// largest widened tfar of its lanes), as bits; `entry` gets each child's
/// lower bound on the entry distance (the order key).
template <int N>
RAYPACK_INLINE std::uint32_t group_child_candidates(const WideNode<N>& node, const GroupIntervals& g, float tfar_hi,
                                                    vfloat<N>& entry) {
    using V = vfloat<N>;
    const V lo[3] = {V::load_aligned(node.bounds[0]), V::load_aligned(node.bounds[1]), V::load_aligned(node.bounds[2])};
    const V hi[3] = {V::load_aligned(node.bounds[3]), V::load_aligned(node.bounds[4]), V::load_aligned(node.bounds[5])};
    return group_box_candidates<N>(lo, hi, g, tfar_hi, entry);
}

/// The boxes of a block's primitives, slot by slot, for the kinds that
/// have a cheap one: triangles (their three vertices; with Moeller's test
/// the block holds p0, p0 - p1 and p2 - p0, else the vertices), spheres and
/// cones. False for the other kinds, whose primitives are all kept.
template <class Kind, TriangleMethod TM, class Block, int M = int(sizeof(Block::prim) / sizeof(Block::prim[0]))>
RAYPACK_INLINE bool slot_boxes(const Block& b, vfloat<M> (&lo)[3], vfloat<M> (&hi)[3]) {
    using V = vfloat<M>;
    if constexpr (Kind::kind == PrimKind::Triangle) {
        for (int a = 0; a < 3; ++a) {
            const V p0 = V::load_unaligned(b.p0[a]), x = V::load_unaligned(b.a[a]), y = V::load_unaligned(b.b[a]);
            const V p1 = TM == TriangleMethod::Moeller ? p0 - x : x, p2 = TM == TriangleMethod::Moeller ? p0 + y : y;
            lo[a] = vmin(vmin(p0, p1), p2);
            hi[a] = vmax(vmax(p0, p1), p2);
        }
        return true;
    } else if constexpr (Kind::kind == PrimKind::Sphere) {
        const V r = vabs(V::load_unaligned(b.radius));
        for (int a = 0; a < 3; ++a) {
            const V c = V::load_unaligned(b.center[a]);
            lo[a] = c - r;
            hi[a] = c + r;
        }
        return true;
    } else if constexpr (Kind::kind == PrimKind::Cone) {
        // The box of the end discs: the surface between them is their
        // convex hull's, radius linear in s. A disc of radius r about unit
        // axis w reaches r sqrt(1 - w_a^2) along axis a. The kernel keeps
        // only r(s) >= 0, so a negative end radius is taken as 0 (the apex
        // of that nappe lies between the ends).
        const V h = V::load_unaligned(b.h), rb = V::load_unaligned(b.rb), zero(0.0f);
        const V r_base = vmax(rb, zero), r_apex = vmax(vfmadd(V::load_unaligned(b.k), h, rb), zero);
        for (int a = 0; a < 3; ++a) {
            const V w = V::load_unaligned(b.w[a]), base = V::load_unaligned(b.base[a]);
            const V apex = vfmadd(w, h, base);
            const V reach = vsqrt(vmax(V(1.0f) - w * w, zero));
            lo[a] = vmin(vfnmadd(r_base, reach, base), vfnmadd(r_apex, reach, apex));
            hi[a] = vmax(vfmadd(r_base, reach, base), vfmadd(r_apex, reach, apex));
        }
        return true;
    } else {
        return false;
    }
}

/// Blocks of a leaf whose primitives' boxes a group tests before its
/// packets do (a leaf with more is tested whole).
constexpr int kMaxCulledBlocks = 8;

/// The primitives of leaf `code` that some ray of the group may meet
/// before `tfar_hi`: a slot mask per block in `slots`, in the order the
/// leaf's runs are visited (packet_leaf). Returns how many primitives are
/// kept, or -1 when the leaf is to be tested whole (too many blocks). Culling
/// a triangle here saves each of the group's packets its test; at 16
/// packets of 8 camera rays on tetra, 60% of a leaf's triangles go
/// (docs/embree.md).
template <TriangleMethod TM, class Kinds, int N, int M>
RAYPACK_INLINE int group_leaf_slots(const WideBvh<N, M>& bvh, std::uint32_t code, const GroupIntervals& g,
                                    float tfar_hi, float pad, std::uint32_t (&slots)[kMaxCulledBlocks]) {
    int blocks = 0, kept = 0;
    bvh.template for_each_run<false, Kinds>(code, [&]<class Kind>(const auto* b, std::uint32_t n) RAYPACK_INLINE_LAMBDA {
        for (std::uint32_t k = 0; k < n && blocks >= 0; ++k, ++b) {
            if (blocks == kMaxCulledBlocks) {
                blocks = -1;
                return true;
            }
            constexpr int BM = int(sizeof(b->prim) / sizeof(b->prim[0]));
            std::uint32_t used = 0;
            for (int j = 0; j < BM && b->prim[j] != kNoPrim; ++j) used |= 1u << j;
            vfloat<BM> lo[3], hi[3];
            std::uint32_t may_hit = used;
            if (slot_boxes<Kind, TM>(*b, lo, hi)) {
                for (int a = 0; a < 3; ++a) {
                    lo[a] = lo[a] - vfloat<BM>(pad);
                    hi[a] = hi[a] + vfloat<BM>(pad);
                }
                vfloat<BM> entry;
                may_hit &= group_box_candidates<BM>(lo, hi, g, tfar_hi, entry);
            }
            slots[blocks++] = may_hit;
            kept += std::popcount(may_hit);
        }
        return false;
    });
    return blocks < 0 ? -1 : kept;
}

/// The largest of the packets' tfar bounds `packet_tfar_hi` over `packets`.
RAYPACK_INLINE float group_tfar_hi(const float* packet_tfar_hi, std::uint32_t packets) {
    float t = -std::numeric_limits<float>::infinity();
    for (; packets != 0; packets &= packets - 1) t = vmax(t, packet_tfar_hi[std::countr_zero(packets)]);
    return t;
}

/// The walk's state of each of the first `count` packets; the entries past
/// them (never used) refer to the first packet, as `p` may hold only `count`.
template <int K, int G, std::size_t... I>
RAYPACK_INLINE std::array<PacketState<K>, G> packet_states(LoadedPacket<K>* p, int count, std::index_sequence<I...>) {
    auto at = [&](std::size_t i) -> LoadedPacket<K>& { return int(i) < count ? p[i] : p[0]; };
    return {PacketState<K>{at(I).hit, at(I).ray.tfar, at(I).valid, at(I).occluded}...};
}
template <int K, int G>
RAYPACK_INLINE std::array<PacketState<K>, G> packet_states(LoadedPacket<K>* p, int count) {
    return packet_states<K, G>(p, count, std::make_index_sequence<G>());
}

/// `count` packets (count <= G <= 32) through the tree together. Any hit
/// with a `cache`: as trace_packet, each packet tests its primitive first.
template <int N, int M, int K, int G, TriangleMethod TM, bool AnyHit, bool ByPrim, class Kinds>
void trace_group(const WideBvh<N, M>& bvh, const PacketKernels<K>& pk, int switch_below, float max_origin_spread,
                 LoadedPacket<K>* p, int count, OccluderCache* cache = nullptr) {
    using F = vfloat<K>;
    PacketNodeRay<K> nr[G];
    const bool together = count > 1 && one_octant<K>(p, count);
    if (together)
        for (int q = 0; q < count; ++q) set_packet_node_ray<K>(p[q].ray, pk.kernels.slabs, nr[q]);
    GroupIntervals g;
    if (!together || !group_intervals<K>(nr, p, count, g) || origin_spread(g) > max_origin_spread) {
        for (int q = 0; q < count; ++q)
            trace_packet<N, M, K, TM, AnyHit, ByPrim, Kinds>(bvh, pk, switch_below, p[q].ray, p[q].hit, p[q].valid,
                                                             p[q].occluded, cache);
        return;
    }
    const SphereMethod sm = pk.kernels.sphere;
    const F minus_inf(-std::numeric_limits<float>::infinity());
    LeafRay<F> lr[G];
    auto s = packet_states<K, G>(p, count);
    float tfar_hi[G];  // per packet: the largest widened tfar of its valid lanes
    std::uint32_t live = 0;
    const bool cached = AnyHit && !ByPrim && cache && !cache->empty();
    for (int q = 0; q < count; ++q) {
        if constexpr (!ByPrim) set_packet_leaf_ray<K>(p[q].ray, TM, lr[q]);
        if constexpr (AnyHit && !ByPrim)
            if (cached && any(s[q].valid)) packet_cached<TM, Kinds, M>(*cache, sm, lr[q], s[q].valid, s[q]);
        tfar_hi[q] = lane_max<K>(select(s[q].valid, node_tfar(s[q].tfar), minus_inf));
        if (any(s[q].valid)) live |= 1u << q;
    }
    if constexpr (AnyHit)
        if (live == 0) return;
    // The group's bound on tfar for the interval test: over every packet
    // still traced, renewed after each leaf.
    float tfar_group = group_tfar_hi(tfar_hi, live);
    const WideNode<N>* nodes = bvh.nodes.data();
    // Stack entries: a child, the packets that enter it, and where its box is
    // (parent node and slot), for the leaves' per-packet box tests.
    constexpr int kStackSize = (N - 1) * kBvhMaxDepth + 1;
    std::uint32_t stack_code[kStackSize], stack_packets[kStackSize], stack_parent[kStackSize];
    int stack_slot[kStackSize];
    float stack_entry[kStackSize];
    int sp = 0;
    std::uint32_t cur = 0, cur_packets = live, parent = 0;
    int slot = 0;
    for (;;) {
        if (wide_child::is_leaf(cur)) {
            const WideNode<N>& box_node = nodes[parent];
            // The primitives no ray of the group can meet, left out for all
            // its packets at once.
            std::uint32_t slots[kMaxCulledBlocks];
            int kept = -1;
            if constexpr (!ByPrim)
                kept = group_leaf_slots<TM, Kinds>(bvh, cur, g, tfar_group, culling_box_pad(box_node.box(slot), g.o_lo, g.o_hi), slots);
            for (std::uint32_t bits = kept == 0 ? 0u : cur_packets; bits != 0; bits &= bits - 1) {
                const int q = std::countr_zero(bits);
                F e;
                const vmask<K> m = child_hits<N, K>(box_node, slot, nr[q], s[q].valid, node_tfar(s[q].tfar), e);
                if (none(m)) continue;
                OccluderCache* const c = AnyHit ? cache : nullptr;
                if constexpr (ByPrim) packet_leaf_by_prim<AnyHit>(bvh, pk.packet, cur, p[q].ray, m, s[q]);
                else if (kept > 0) packet_leaf<TM, AnyHit, Kinds, true>(bvh, sm, cur, lr[q], m, s[q], slots, c);
                else packet_leaf<TM, AnyHit, Kinds>(bvh, sm, cur, lr[q], m, s[q], nullptr, c);
                tfar_hi[q] = lane_max<K>(select(s[q].valid, node_tfar(s[q].tfar), minus_inf));
                if constexpr (AnyHit)
                    if (none(s[q].valid)) live &= ~(1u << q);
            }
            if constexpr (AnyHit)
                if (live == 0) return;
            tfar_group = group_tfar_hi(tfar_hi, live);
        } else {
            const WideNode<N>& node = nodes[cur];
            vfloat<N> entry_v;
            std::uint32_t candidates = group_child_candidates<N>(node, g, tfar_group, entry_v);
            alignas(64) float entry[N];
            entry_v.store_aligned(entry);
            std::uint32_t child_packets[N];
            int hit_slot[N], n_hit = 0;
            for (; candidates != 0; candidates &= candidates - 1) {
                const int i = std::countr_zero(candidates);
                // The first and the last packet that meet child i, and those between.
                std::uint32_t bits = cur_packets;
                for (; bits != 0; bits &= bits - 1) {
                    const int q = std::countr_zero(bits);
                    F e;
                    if (any(child_hits<N, K>(node, i, nr[q], s[q].valid, node_tfar(s[q].tfar), e))) break;
                }
                if (bits == 0) continue;
                for (std::uint32_t rest = bits & (bits - 1); rest != 0;) {
                    const int q = 31 - std::countl_zero(rest);
                    F e;
                    if (any(child_hits<N, K>(node, i, nr[q], s[q].valid, node_tfar(s[q].tfar), e))) break;
                    rest &= ~(1u << q);
                    bits &= ~(1u << q);
                }
                child_packets[n_hit] = bits;
                hit_slot[n_hit++] = i;
            }
            if (n_hit != 0) {
                // Nearest first by the group's entry bound; push the others farthest first.
                int order[N];
                for (int c = 0; c < n_hit; ++c) {
                    int at = c;
                    if constexpr (!AnyHit)
                        for (; at > 0 && entry[hit_slot[order[at - 1]]] > entry[hit_slot[c]]; --at) order[at] = order[at - 1];
                    order[at] = c;
                }
                for (int c = n_hit - 1; c > 0; --c) {
                    const int i = hit_slot[order[c]];
                    stack_code[sp] = node.child[i];
                    stack_packets[sp] = child_packets[order[c]];
                    stack_parent[sp] = cur;
                    stack_slot[sp] = i;
                    stack_entry[sp++] = entry[i];
                }
                parent = cur;
                slot = hit_slot[order[0]];
                cur_packets = child_packets[order[0]];
                cur = node.child[slot];
                continue;
            }
        }
        // Pop the next child the group may still meet before its closest hits.
        for (;;) {
            if (sp == 0) {
                if constexpr (AnyHit) {
                    bool any_occluded = false;
                    for (int q = 0; q < count; ++q) any_occluded |= any(p[q].occluded & p[q].valid);
                    if (cache && !any_occluded) cache->clear();
                }
                return;
            }
            --sp;
            cur_packets = stack_packets[sp] & live;
            if (cur_packets != 0 && !(stack_entry[sp] > tfar_group)) break;
        }
        cur = stack_code[sp];
        parent = stack_parent[sp];
        slot = stack_slot[sp];
    }
}

}  // namespace raypack::wide_packet_detail

namespace raypack {

namespace wide_packet_detail {

/// wide_trace_packets (AnyHit false, `hits` a std::span<Hitf>) and
/// wide_occluded_packets (true, a std::span<std::uint8_t>).
template <int N, int M, int K, bool AnyHit, class Answers>
void trace_packets_into(const WideBvh<N, M>& bvh, const Scene& scene, KernelChoice kernels,
                        const WidePacketConfig& config, std::span<const Rayf> rays, Answers hits) {
    if (bvh.nodes.empty()) {
        for (auto& h : hits) h = {};
        return;
    }
    const wide_packet_detail::PacketKernels<K> pk{kernels, {&scene, kernels}, {&scene, kernels}};
    // Any hit: the primitive that stopped the last occluded ray, for the
    // next packets. Not with plain slabs, which may miss the box of a
    // primitive that the cache would test anyway: packets must answer as
    // the single rays do.
    OccluderCache occluder_cache;
    OccluderCache* const cache =
        AnyHit && config.occluder_cache && kernels.slabs != SlabMethod::Plain ? &occluder_cache : nullptr;
    auto run = [&]<TriangleMethod TM, bool ByPrim, class Kinds = PrimKinds>() {
        auto trace_packet = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
            wide_packet_detail::trace_packet<N, M, K, TM, AnyHit, ByPrim, Kinds>(bvh, pk, config.switch_below, ray, hit,
                                                                                 valid, occluded, cache);
        };
        if (config.group_packets > 1) {
            constexpr int G = WidePacketConfig::kMaxGroupPackets;
            const int group = std::min(config.group_packets, G);
            const float max_spread = wide_packet_detail::max_origin_spread(bvh);
            // trace_in_groups takes its group size at compile time; a smaller
            // configured group is cut from the loaded one.
            trace_in_groups<K, G, AnyHit>(
                rays, hits, kernels.rcp,
                [](const LoadedPacket<K>& p) { return wide_packet_detail::one_octant<K>(&p, 1); }, trace_packet,
                [&](LoadedPacket<K>* p, int count) {
                    for (int first = 0; first < count; first += group)
                        wide_packet_detail::trace_group<N, M, K, G, TM, AnyHit, ByPrim, Kinds>(
                            bvh, pk, config.switch_below, max_spread, p + first, std::min(group, count - first), cache);
                });
            return;
        }
        trace_in_packets<K, AnyHit>(rays, hits, kernels.rcp, trace_packet);
    };
    // Double: leaves test primitives by id, so one instantiation serves every
    // triangle method (as in WideBvhAccel::trace).
    if (kernels.precision == Precision::Double) return run.template operator()<TriangleMethod::Moeller, true>();
    if (specialisation_for(scene, kernels) == KindSpecialisation::Triangles)
        return run.template operator()<TriangleMethod::Moeller, false, TriangleKinds>();
    switch (kernels.triangle) {
        case TriangleMethod::Moeller: return run.template operator()<TriangleMethod::Moeller, false>();
        case TriangleMethod::Watertight: return run.template operator()<TriangleMethod::Watertight, false>();
        case TriangleMethod::Plane: return run.template operator()<TriangleMethod::Plane, false>();
    }
}

}  // namespace wide_packet_detail

template <int N, int M, int K>
void wide_trace_packets(const WideBvh<N, M>& bvh, const Scene& scene, KernelChoice kernels,
                        const WidePacketConfig& config, std::span<const Rayf> rays, std::span<Hitf> hits) {
    wide_packet_detail::trace_packets_into<N, M, K, false>(bvh, scene, kernels, config, rays, hits);
}

template <int N, int M, int K>
void wide_occluded_packets(const WideBvh<N, M>& bvh, const Scene& scene, KernelChoice kernels,
                           const WidePacketConfig& config, std::span<const Rayf> rays,
                           std::span<std::uint8_t> occluded) {
    wide_packet_detail::trace_packets_into<N, M, K, true>(bvh, scene, kernels, config, rays, occluded);
}

}  // namespace raypack
