#pragma once
// The packet traversal of accel/bvh/wide_packet.h, included only by the
// .cpp files that instantiate it.
//
// One packet of K rays descends the N-wide tree together: each child box is
// tested against all active lanes (K rays x 1 box), a child is entered by
// the lanes that meet it before their current closest hit, and the hit
// children are visited nearest first for the first active lane ("first
// active" ordering: wide nodes store no split axis, so the order comes from
// that lane's entry distances). Leaves test each primitive against the
// active lanes (K rays x 1 primitive, broadcast from the leaf block). When
// fewer than WidePacketConfig::switch_below lanes reach a node, each of them
// finishes that subtree as a single ray (Benthin et al. 2012), with the
// single-ray wide traversal and its 1 x N node and 1 x M block tests.
//
// Results: the node test is the single-ray Ordered test lane by lane (same
// planes, same widened reciprocals, same operand order), and the primitive
// kernels are the single-ray ones with ray and primitive swapped between
// broadcast and lanes, so every (ray, primitive) pair gives bit-identical
// t, u, v and hit/miss, and hit/miss and occlusion per ray are the single
// ray's. What may differ is which of two nearly coincident hits is kept:
// leaves are visited in another order, boxes are culled against the closest
// hit so far, and neither a box's entry distance nor a kernel's t is exact,
// so a primitive whose computed t lies a few ulps (at grazing angles more)
// before another's may be culled in one order and not in the other. Among
// hits at exactly the same t, a block keeps the last for the packet and the
// first for the single ray. tests/test_wide_bvh_packet.cpp checks this.
//
// SIMD locals here are not `const`: gcc 12 does not split a const aggregate
// into registers ("store to a read-only decl" in -fdump-tree-sra-details),
// and the triangle test then stored its broadcast vertices to the stack on
// every iteration (docs/embree.md).
#include <bit>
#include <cmath>
#include <algorithm>
#include <cstdint>
#include <limits>

#include "accel/bvh/wide_packet.h"
#include "accel/bvh/wide_traversal.h"
#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "kernels/ray_packet.h"

namespace raypack::wide_packet_detail {

/// x with its bits plus one: the next float away from zero (finite x).
template <class F>
RAYPACK_INLINE F next_away_from_zero(const F& x) {
    if constexpr (sizeof(F) == 16) {
        return _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(x), _mm_set1_epi32(1)));
    } else if constexpr (sizeof(F) == 32) {
        return _mm256_castsi256_ps(_mm256_add_epi32(_mm256_castps_si256(x), _mm256_set1_epi32(1)));
    } else {
#if defined(__AVX512F__)
        return _mm512_castsi512_ps(_mm512_add_epi32(_mm512_castps_si512(x), _mm512_set1_epi32(1)));
#endif
    }
}

/// The far-plane reciprocals of the Ordered node test from the near ones
/// `r`: widened by kFarWiden and one ulp away from zero (robust slabs,
/// Ize 2013), or `r` itself (plain slabs).
template <int K>
RAYPACK_INLINE vfloat<K> far_reciprocal(const vfloat<K>& r, bool widen) {
    using F = vfloat<K>;
    if (!widen) return r;
    F w = r * F(kFarWiden);
    return select(vabs(w) == F(std::numeric_limits<float>::infinity()), w, next_away_from_zero(w));
}

/// The packet as the node and leaf tests see it, computed once per packet.
template <int K>
struct PacketNodeRay {
    using F = vfloat<K>;
    Vec3<F> org, rdir, rdir_far;
    vmask<K> neg_x, neg_y, neg_z;  ///< rdir < 0: the near plane is hi
    F tnear;
};

/// make_node_ray<NodeTest::Ordered> (accel/bvh/wide_node_test.h) for K
/// lanes: the same reciprocal (load_packet's, computed per ray by `--rcp`;
/// unclamped it is 1 / d, the single ray's bits), the same +-inf for a
/// clamped component, the same far reciprocal (widened unless `slabs` is
/// Plain).
/// Written in place: a group fills sixteen of them, and assigning returned
/// ones copied each through memmove (4-5% of a shadow-ray pass).
template <int K>
RAYPACK_INLINE void set_packet_node_ray(const RayPacket<K>& p, SlabMethod slabs, PacketNodeRay<K>& n) {
    using F = vfloat<K>;
    F inf(std::numeric_limits<float>::infinity());
    const bool widen = slabs == SlabMethod::Robust;
    auto axis = [&](const F& d, const F& rd, F& r, F& r_far, vmask<K>& negative) {
        r = select(vabs(d) < F(kMinRcpInput), copysign_of(inf, d), rd);
        r_far = far_reciprocal<K>(r, widen);
        negative = r < F(0.0f);
    };
    axis(p.dir.x, p.rdir.x, n.rdir.x, n.rdir_far.x, n.neg_x);
    axis(p.dir.y, p.rdir.y, n.rdir.y, n.rdir_far.y, n.neg_y);
    axis(p.dir.z, p.rdir.z, n.rdir.z, n.rdir_far.z, n.neg_z);
    n.org = p.org;
    n.tnear = p.tnear;
}
template <int K>
RAYPACK_INLINE PacketNodeRay<K> make_packet_node_ray(const RayPacket<K>& p, SlabMethod slabs) {
    PacketNodeRay<K> n;
    set_packet_node_ray<K>(p, slabs, n);
    return n;
}

/// make_leaf_ray for K lanes (in place, as set_packet_node_ray).
template <int K>
RAYPACK_INLINE void set_packet_leaf_ray(const RayPacket<K>& p, TriangleMethod method, LeafRay<vfloat<K>>& l) {
    using F = vfloat<K>;
    l.org = p.org;
    l.dir = p.dir;
    l.tnear = p.tnear;
    l.dd = fused_dot(p.dir, p.dir);
    l.inv_dd = F(1.0f) / l.dd;
    if (method == TriangleMethod::Watertight) l.watertight = make_watertight_ray<F>(p.org, p.dir);
}
template <int K>
RAYPACK_INLINE LeafRay<vfloat<K>> make_packet_leaf_ray(const RayPacket<K>& p, TriangleMethod method) {
    LeafRay<vfloat<K>> l;
    set_packet_leaf_ray<K>(p, method, l);
    return l;
}

/// Lanes of `active` that meet child box i of `node` before their `tfar`;
/// `entry` gets the entry distances. Lane for lane the single-ray Ordered
/// test: the near plane per axis picked by the lane's direction sign, NaN
/// dropped by operand order.
template <int N, int K>
RAYPACK_INLINE vmask<K> child_hits(const WideNode<N>& node, int i, const PacketNodeRay<K>& r, const vmask<K>& active,
                                   const vfloat<K>& tfar, vfloat<K>& entry) {
    using F = vfloat<K>;
    F lx(node.bounds[0][i]), ly(node.bounds[1][i]), lz(node.bounds[2][i]);
    F hx(node.bounds[3][i]), hy(node.bounds[4][i]), hz(node.bounds[5][i]);
    F nx = (select(r.neg_x, hx, lx) - r.org.x) * r.rdir.x;
    F ny = (select(r.neg_y, hy, ly) - r.org.y) * r.rdir.y;
    F nz = (select(r.neg_z, hz, lz) - r.org.z) * r.rdir.z;
    F fx = (select(r.neg_x, lx, hx) - r.org.x) * r.rdir_far.x;
    F fy = (select(r.neg_y, ly, hy) - r.org.y) * r.rdir_far.y;
    F fz = (select(r.neg_z, lz, hz) - r.org.z) * r.rdir_far.z;
    entry = vmax(vmax(nx, ny), vmax(nz, r.tnear));
    F exit = vmin(vmin(fx, fy), vmin(fz, tfar));
    return active & (entry <= exit);
}

/// The per-packet state the leaves update: the closest hits so far, each
/// lane's tfar (its closest t; -inf once an any-hit lane is occluded), the
/// lanes still traced and, for any hit, the occluded ones.
template <int K>
struct PacketState {
    using F = vfloat<K>;
    HitPacket<K>& hit;
    F tfar;
    vmask<K> valid;
    vmask<K>& occluded;
};

/// A run of blocks of kind Kind against the active lanes, one primitive at
/// a time (padding lanes, prim = kNoPrim, end a block). Masked: only the
/// primitives whose bits are set in slots[k] for the run's block k (a group
/// of packets leaves out those none of its rays can meet,
/// wide_group_traversal.h); the others are tested in the same order.
template <class Kind, TriangleMethod TM, bool AnyHit, bool Masked = false, int K, class Block>
RAYPACK_INLINE void packet_run(const Block* b, std::uint32_t count, SphereMethod sm, const LeafRay<vfloat<K>>& r,
                               vmask<K> active, PacketState<K>& s, const std::uint32_t* slots = nullptr,
                               OccluderCache* cache = nullptr) {
    using F = vfloat<K>;
    constexpr int M = int(sizeof(b->prim) / sizeof(b->prim[0]));
    F minus_inf(-std::numeric_limits<float>::infinity());
    for (; count != 0; --count, ++b) {
        [[maybe_unused]] std::uint32_t may_hit = 0;  // Masked: the block's slots still to test
        if constexpr (Masked) may_hit = *slots++;
        for (int j = 0; j < M && b->prim[j] != kNoPrim; ++j) {
            if constexpr (Masked)
                if (!((may_hit >> j) & 1u)) continue;
            F t(0.0f), u(0.0f), v(0.0f);  // the kernels set only their hit lanes
            [[maybe_unused]] std::uint32_t ids[names_hits<Kind> ? K : 1];
            vmask<K> m;
            if constexpr (names_hits<Kind>) m = Kind::template intersect_slot<TM, F, M>(*b, j, sm, r, active, s.tfar, t, u, v, ids);
            else m = Kind::template intersect_slot<TM, F, M>(*b, j, sm, r, active, s.tfar, t, u, v);
            if (none(m)) continue;
            if constexpr (AnyHit) {
                if (cache) cache->set<Kind>(b, j);
                s.occluded = s.occluded | m;
                s.valid = s.valid & !m;
                s.tfar = select(m, minus_inf, s.tfar);
                active = active & !m;
                if (none(active)) return;
            } else {
                s.hit.t = select(m, t, s.hit.t);
                s.hit.u = select(m, u, s.hit.u);
                s.hit.v = select(m, v, s.hit.v);
                s.tfar = select(m, t, s.tfar);
                for (std::uint32_t bits = mask_bits(m); bits != 0; bits &= bits - 1) {
                    const int l = std::countr_zero(bits);
                    if constexpr (names_hits<Kind>) s.hit.prim[l] = ids[l];
                    else s.hit.prim[l] = b->prim[j];
                }
            }
        }
    }
}

/// The blocks of one leaf against the active lanes (any hit: each run
/// against the lanes not yet occluded).
/// Masked: `slots` holds a mask per block, in the order of the leaf's runs
/// (packet_run).
template <TriangleMethod TM, bool AnyHit, class Kinds, bool Masked = false, int N, int M, int K>
RAYPACK_INLINE void packet_leaf(const WideBvh<N, M>& bvh, SphereMethod sm, std::uint32_t code,
                                const LeafRay<vfloat<K>>& r, const vmask<K>& active, PacketState<K>& s,
                                const std::uint32_t* slots = nullptr, OccluderCache* cache = nullptr) {
    bvh.template for_each_run<false, Kinds>(code, [&]<class Kind>(const auto* blocks, std::uint32_t n) RAYPACK_INLINE_LAMBDA {
        packet_run<Kind, TM, AnyHit, Masked>(blocks, n, sm, r, AnyHit ? active & s.valid : active, s, slots, cache);
        if constexpr (Masked) slots += n;
        return false;
    });
}

/// The cached primitive (OccluderCache, not empty) against the active lanes
/// of an any-hit packet: the occluded ones leave `s.valid`.
template <TriangleMethod TM, class Kinds, int M, int K>
RAYPACK_INLINE void packet_cached(const OccluderCache& cache, SphereMethod sm, const LeafRay<vfloat<K>>& r,
                                  vmask<K> active, PacketState<K>& s) {
    using F = vfloat<K>;
    Kinds::dispatch(cache.kind, [&]<class Kind>() RAYPACK_INLINE_LAMBDA {
        const auto* b = static_cast<const typename Kind::template Block<M>*>(cache.block);
        F t(0.0f), u(0.0f), v(0.0f);
        vmask<K> m;
        if constexpr (names_hits<Kind>) {
            std::uint32_t ids[K];
            m = Kind::template intersect_slot<TM, F, M>(*b, cache.slot, sm, r, active, s.tfar, t, u, v, ids);
        } else {
            m = Kind::template intersect_slot<TM, F, M>(*b, cache.slot, sm, r, active, s.tfar, t, u, v);
        }
        s.occluded = s.occluded | m;
        s.valid = s.valid & !m;
        s.tfar = select(m, F(-std::numeric_limits<float>::infinity()), s.tfar);
    });
}

/// packet_leaf for --precision double: each primitive of the leaf's blocks,
/// by id, through PacketPrimitiveIntersector (double, lane by lane).
template <bool AnyHit, int N, int M, int K>
inline void packet_leaf_by_prim(const WideBvh<N, M>& bvh, const PacketPrimitiveIntersector<vfloat<K>>& isect,
                                std::uint32_t code, const RayPacket<K>& ray, vmask<K> active, PacketState<K>& s) {
    using F = vfloat<K>;
    F minus_inf(-std::numeric_limits<float>::infinity());
    RayPacket<K> r = ray;
    bvh.template for_each_run<false>(code, [&]<class Kind>(const auto* b, std::uint32_t count) {
        constexpr int BM = int(sizeof(b->prim) / sizeof(b->prim[0]));
        for (; count != 0; --count, ++b) {
            for (int j = 0; j < BM && b->prim[j] != kNoPrim; ++j) {
                if (none(active)) return false;
                r.tfar = s.tfar;
                vmask<K> m = isect.intersect(active, r, s.hit, b->prim[j]);
                if constexpr (AnyHit) {
                    s.occluded = s.occluded | m;
                    s.valid = s.valid & !m;
                    s.tfar = select(m, minus_inf, s.tfar);
                    active = active & !m;
                } else {
                    s.tfar = r.tfar;
                }
            }
        }
        return false;
    });
}

/// What the packet traversal needs beyond the tree: the kernel variants and,
/// for --precision double (ByPrim), the primitive intersectors.
template <int K>
struct PacketKernels {
    KernelChoice kernels;
    PrimitiveIntersector<float> single;
    PacketPrimitiveIntersector<vfloat<K>> packet;
};

/// The lanes `bits` finish the subtree under `root` one ray at a time
/// (Benthin et al. 2012), each from its own closest hit so far. Any hit:
/// each lane tests the cached primitive's block first, and the primitive
/// that stops a lane becomes the cache's.
template <int N, int M, int K, TriangleMethod TM, bool AnyHit, bool ByPrim, class Kinds>
void lanes_alone(const WideBvh<N, M>& bvh, const PacketKernels<K>& pk, std::uint32_t root, std::uint32_t bits,
                 const RayPacket<K>& ray, PacketState<K>& s, OccluderCache* cache) {
    using F = vfloat<K>;
    alignas(64) float org[3][K], dir[3][K], tnear[K], tfar[K], t[K], u[K], v[K];
    for (int a = 0; a < 3; ++a) {
        ray.org[a].store_aligned(org[a]);
        ray.dir[a].store_aligned(dir[a]);
    }
    ray.tnear.store_aligned(tnear);
    s.tfar.store_aligned(tfar);
    s.hit.t.store_aligned(t);
    s.hit.u.store_aligned(u);
    s.hit.v.store_aligned(v);
    std::uint32_t occluded = 0;
    for (; bits != 0; bits &= bits - 1) {
        const int i = std::countr_zero(bits);
        Rayf r;
        r.org = {org[0][i], org[1][i], org[2][i]};
        r.dir = {dir[0][i], dir[1][i], dir[2][i]};
        r.tnear = tnear[i];
        r.tfar = tfar[i];
        Hitf h{t[i], s.hit.prim[i], u[i], v[i]};
        float lane_tfar = tfar[i];
        const NodeRay<N> nr = make_node_ray<NodeTest::Ordered, N>(r, pk.kernels.slabs, pk.kernels.rcp);
        bool lane_hit;
        if constexpr (ByPrim) {
            const PrimLeafRay p{&pk.single, r};
            lane_hit = trace_wide_subtree<N, M, TM, NodeTest::Ordered, AnyHit, true>(
                bvh, pk.kernels.sphere, root, nr, LeafRay<vfloat<M>>{}, lane_tfar, h, &p);
        } else {
            const LeafRay<vfloat<M>> lr = make_leaf_ray<vfloat<M>>(r, TM);
            lane_hit = false;
            if constexpr (AnyHit) {
                if (cache && !cache->empty())
                    lane_hit = occluded_by_cached<TM, Kinds, M>(*cache, pk.kernels.sphere, lr, lane_tfar, h);
            }
            if (!lane_hit)
                lane_hit = trace_wide_subtree<N, M, TM, NodeTest::Ordered, AnyHit, false, NoTraversalCounts, Kinds>(
                    bvh, pk.kernels.sphere, root, nr, lr, lane_tfar, h, nullptr, {}, AnyHit ? cache : nullptr);
        }
        if (!lane_hit) continue;
        if constexpr (AnyHit) {
            occluded |= 1u << i;
            tfar[i] = -std::numeric_limits<float>::infinity();
        } else {
            tfar[i] = lane_tfar;
            t[i] = h.t;
            u[i] = h.u;
            v[i] = h.v;
            s.hit.prim[i] = h.prim;
        }
    }
    s.tfar = F::load_aligned(tfar);
    if constexpr (AnyHit) {
        if (occluded != 0) {
            vmask<K> m = mask_from_bits<K>(occluded);
            s.occluded = s.occluded | m;
            s.valid = s.valid & !m;
        }
    } else {
        s.hit.t = F::load_aligned(t);
        s.hit.u = F::load_aligned(u);
        s.hit.v = F::load_aligned(v);
    }
}

/// One packet through the tree, with leaves compiled for Kinds.
/// Any hit with a `cache` (OccluderCache): the packet tests its primitive
/// first, and the last primitive that stops a lane becomes the cache's; a
/// packet none of whose lanes is stopped empties it, so that scenes with
/// few shadows pay no test.
template <int N, int M, int K, TriangleMethod TM, bool AnyHit, bool ByPrim, class Kinds>
void trace_packet(const WideBvh<N, M>& bvh, const PacketKernels<K>& pk, int switch_below, const RayPacket<K>& ray,
                  HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded, OccluderCache* cache = nullptr) {
    using F = vfloat<K>;
    using B = vmask<K>;
    const SphereMethod sm = pk.kernels.sphere;
    const PacketNodeRay<K> nr = make_packet_node_ray<K>(ray, pk.kernels.slabs);
    const LeafRay<F> lr = make_packet_leaf_ray<K>(ray, TM);
    PacketState<K> s{hit, ray.tfar, valid, occluded};
    const WideNode<N>* nodes = bvh.nodes.data();
    F nan(std::numeric_limits<float>::quiet_NaN());
    // Stack entries: a child and its lanes' entry distances, NaN in the
    // lanes that missed it, so that `entry <= tfar` at the pop is exactly
    // the lanes that meet it before their closest hit so far.
    constexpr int kStackSize = (N - 1) * kBvhMaxDepth + 1;
    alignas(64) float stack_entry[kStackSize][K];
    std::uint32_t stack_node[kStackSize];
    int sp = 0;
    std::uint32_t cur = 0;
    B active = valid;
    if constexpr (AnyHit && !ByPrim) {
        if (cache && !cache->empty()) {
            packet_cached<TM, Kinds, M>(*cache, sm, lr, active, s);
            if (none(s.valid)) return;
            active = s.valid;
        }
    }
    for (;;) {
        for (;;) {
            const std::uint32_t bits = mask_bits(active);
            if (std::popcount(bits) < switch_below) {
                lanes_alone<N, M, K, TM, AnyHit, ByPrim, Kinds>(bvh, pk, cur, bits, ray, s, cache);
                break;
            }
            if (wide_child::is_leaf(cur)) {
                if constexpr (ByPrim) {
                    packet_leaf_by_prim<AnyHit>(bvh, pk.packet, cur, ray, active, s);
                } else {
                    packet_leaf<TM, AnyHit, Kinds>(bvh, sm, cur, lr, active, s, nullptr, AnyHit ? cache : nullptr);
                }
                break;
            }
            const WideNode<N>& node = nodes[cur];
            const int first_lane = std::countr_zero(bits);
            // Test every child against the active lanes; keep the hit ones.
            alignas(64) float entry[N][K];
            std::uint32_t child[N];
            float key[N];
            int count = 0;
            F tfar_nodes = node_tfar(s.tfar);
            for (int i = 0; i < N; ++i) {
                if (node.child[i] == wide_child::kEmpty) continue;
                F e;
                B m = child_hits<N, K>(node, i, nr, active, tfar_nodes, e);
                const std::uint32_t mb = mask_bits(m);
                if (mb == 0) continue;
                select(m, e, nan).store_aligned(entry[count]);
                child[count] = node.child[i];
                // Order key: the first active lane's entry distance (children
                // it misses go after the ones it meets, in slot order).
                key[count] = (mb >> first_lane) & 1u ? entry[count][first_lane] : std::numeric_limits<float>::max();
                ++count;
            }
            if (count == 0) break;
            // Push all but the nearest, farthest first; descend into the nearest.
            int order[N];
            for (int c = 0; c < count; ++c) {
                int p = c;
                if constexpr (!AnyHit)
                    for (; p > 0 && key[order[p - 1]] > key[c]; --p) order[p] = order[p - 1];
                order[p] = c;
            }
            for (int c = count - 1; c > 0; --c) {
                std::copy(entry[order[c]], entry[order[c]] + K, stack_entry[sp]);
                stack_node[sp++] = child[order[c]];
            }
            F e0 = F::load_aligned(entry[order[0]]);
            active = e0 == e0;  // not NaN: the lanes that met it
            cur = child[order[0]];
        }
        if constexpr (AnyHit)
            if (none(s.valid)) return;
        // Pop the next child some lane still meets before its closest hit.
        for (;;) {
            if (sp == 0) {
                if constexpr (AnyHit)
                    if (cache && none(s.occluded & valid)) cache->clear();
                return;
            }
            --sp;
            active = s.valid & (F::load_aligned(stack_entry[sp]) <= node_tfar(s.tfar));
            if (any(active)) break;
        }
        cur = stack_node[sp];
    }
}

}  // namespace raypack::wide_packet_detail
