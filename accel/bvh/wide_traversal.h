#pragma once
// One ray through an N-wide BVH: all N child boxes in one SIMD slab test,
// the hit children pushed so that the nearest is visited first (closest hit;
// any hit takes them as they come), a fixed-size stack, and leaves tested M
// primitives at a time (Wald, Benthin, Boulos,
// "Getting Rid of Packets", RT 2008; Dammertz et al. 2008; Ernst & Greiner
// 2008; Embree's BVHNIntersector1).
#include <bit>
#include <cmath>
#include <cstdint>

#include "accel/bvh/bvh2.h"  // kBvhMaxDepth
#include "accel/bvh/wide_bvh.h"
#include "accel/bvh/wide_node_test.h"
#include "accel/traversal_counts.h"

namespace raypack {

/// Stack entries: a child and its entry distance, so that a pop can skip
/// nodes entered beyond the closest hit found since the push.
struct WideStackEntry {
    std::uint32_t node;
    float dist;
};

/// The primitive that stopped the last occluded ray of an any-hit query
/// (its block and slot), tested first by the rays that follow: shadow rays
/// from neighbouring points toward one light are mostly stopped by the same
/// primitive (the shadow cache of Haines & Greenberg, "The Light Buffer: A
/// Shadow-Testing Accelerator", IEEE CG&A 1986, here per query and with the
/// walk's own kernels). Answers are unchanged: any occluder is one.
struct OccluderCache {
    const void* block = nullptr;  ///< a Kind::Block<M> of the tree, or none
    PrimKind kind{};
    int slot = 0;

    bool empty() const { return block == nullptr; }
    void clear() { block = nullptr; }
    template <class Kind, class Block>
    RAYPACK_INLINE void set(const Block* b, int j) {
        block = b;
        kind = Kind::kind;
        slot = j;
    }
};

/// The nearest hit among the lanes `bits` of a block: records it and
/// shrinks tfar.
template <class F>
RAYPACK_INLINE void record_nearest(std::uint32_t bits, const F& t, const F& u, const F& v,
                                   const std::uint32_t* prim, float& tfar, Hitf& hit) {
    alignas(64) float ts[lanes_of<F>];
    t.store_aligned(ts);
    int best = std::countr_zero(bits);
    for (bits &= bits - 1; bits != 0; bits &= bits - 1) {
        const int i = std::countr_zero(bits);
        if (ts[i] < ts[best]) best = i;
    }
    hit.t = tfar = ts[best];
    hit.u = lane(u, best);
    hit.v = lane(v, best);
    hit.prim = prim[best];
}

/// Tests a run of blocks of kind Kind; true if something was hit (any hit:
/// stops at the first). `count` sees each block tested.
template <class Kind, TriangleMethod TM, bool AnyHit, int M, class Count>
RAYPACK_INLINE bool intersect_run(const typename Kind::template Block<M>* b, std::uint32_t n, SphereMethod sm,
                                  const LeafRay<vfloat<M>>& r, float& tfar, Hitf& hit, Count& count,
                                  OccluderCache* cache = nullptr) {
    using F = vfloat<M>;
    bool found = false;
    for (; n != 0; --n, ++b) {
        count.block(b->prim);
        F t(0.0f), u(0.0f), v(0.0f);  // set by the kernel on hit lanes only
        if constexpr (names_hits<Kind>) {
            alignas(64) std::uint32_t ids[M];
            const std::uint32_t bits =
                mask_bits(Kind::template intersect_block<TM, F, M>(*b, sm, r, F(tfar), t, u, v, ids));
            if (bits == 0) continue;
            if constexpr (AnyHit) {
                if (cache) cache->set<Kind>(b, std::countr_zero(bits));
                return true;
            }
            found = true;
            record_nearest(bits, t, u, v, ids, tfar, hit);
        } else {
            const std::uint32_t bits =
                mask_bits(Kind::template intersect_block<TM, F, M>(*b, sm, r, F(tfar), t, u, v));
            if (bits == 0) continue;
            if constexpr (AnyHit) {
                if (cache) cache->set<Kind>(b, std::countr_zero(bits));
                return true;
            }
            found = true;
            record_nearest(bits, t, u, v, b->prim, tfar, hit);
        }
    }
    return found;
}

/// --precision double: what a leaf needs to test its blocks' primitives one
/// by one, by id, through PrimitiveIntersector<float> (which runs them in
/// double) instead of the float block kernels.
struct PrimLeafRay {
    const PrimitiveIntersector<float>* isect;
    Rayf ray;  ///< tfar is replaced by the current closest hit at each test
};

template <bool AnyHit, class Block, class Count>
RAYPACK_INLINE bool intersect_run_by_prim(const Block* b, std::uint32_t n, const PrimLeafRay& p, float& tfar,
                                          Hitf& hit, Count& count) {
    constexpr int M = int(sizeof(b->prim) / sizeof(b->prim[0]));
    bool found = false;
    for (; n != 0; --n, ++b) {
        count.block(b->prim);
        for (int j = 0; j < M && b->prim[j] != kNoPrim; ++j) {  // padding ends a block
            Rayf r = p.ray;
            r.tfar = tfar;
            if (!p.isect->intersect(b->prim[j], r, hit)) continue;
            if constexpr (AnyHit) return true;
            found = true;
            tfar = r.tfar;
        }
    }
    return found;
}

/// Tests the blocks of one leaf, through the block kernels or, ByPrim
/// (--precision double), by id; true if something was hit.
template <TriangleMethod TM, bool AnyHit, bool ByPrim, class Kinds, int N, int M, class Count>
RAYPACK_INLINE bool intersect_leaf(const WideBvh<N, M>& bvh, SphereMethod sm, std::uint32_t code,
                                   const LeafRay<vfloat<M>>& r, const PrimLeafRay* by_prim, float& tfar, Hitf& hit,
                                   Count& count, OccluderCache* cache = nullptr) {
    count.node();
    count.leaf();
    return bvh.template for_each_run<AnyHit, Kinds>(code, [&]<class Kind>(const auto* blocks, std::uint32_t n)
                                                        RAYPACK_INLINE_LAMBDA {
        if constexpr (ByPrim) return intersect_run_by_prim<AnyHit>(blocks, n, *by_prim, tfar, hit, count);
        else return intersect_run<Kind, TM, AnyHit, M>(blocks, n, sm, r, tfar, hit, count, cache);
    });
}

/// Whether the cached primitive's block stops the ray (any hit; the cache
/// is not empty).
template <TriangleMethod TM, class Kinds, int M>
RAYPACK_INLINE bool occluded_by_cached(const OccluderCache& cache, SphereMethod sm, const LeafRay<vfloat<M>>& r,
                                       float& tfar, Hitf& hit) {
    return Kinds::dispatch(cache.kind, [&]<class Kind>() RAYPACK_INLINE_LAMBDA {
        NoTraversalCounts no_counts;
        return intersect_run<Kind, TM, true, M>(static_cast<const typename Kind::template Block<M>*>(cache.block), 1,
                                                sm, r, tfar, hit, no_counts);
    });
}

/// One ray through the subtree under child slot `root` (an inner node or a
/// leaf), with `tfar` the current closest hit distance (shrunk on hits) and
/// `hit` the current closest hit: the traversal of trace_wide, and the
/// single-ray fallback of the packet traversal (accel/bvh/wide_packet.h).
/// True if it found a hit (any hit: returns at the first). ByPrim: leaves
/// go through `by_prim` (--precision double), not the block kernels.
/// `count` sees each node and leaf entered and each block tested
/// (count_traversal); NoTraversalCounts compiles away. Kinds: the kinds the
/// loop is compiled for (KindSpecialisation). Any hit: `cache`, if given,
/// gets the primitive that stopped the ray.
template <int N, int M, TriangleMethod TM, NodeTest Test, bool AnyHit, bool ByPrim = false,
          class Count = NoTraversalCounts, class Kinds = PrimKinds>
RAYPACK_INLINE bool trace_wide_subtree(const WideBvh<N, M>& bvh, SphereMethod sphere_method, std::uint32_t root,
                                       const NodeRay<N>& nr, const LeafRay<vfloat<M>>& lr, float& tfar, Hitf& hit,
                                       const PrimLeafRay* by_prim = nullptr, Count count = {},
                                       OccluderCache* cache = nullptr) {
    using F = vfloat<N>;
    // Every level but the leaves pushes at most N - 1 entries.
    constexpr int kStackSize = (N - 1) * kBvhMaxDepth + 1;
    WideStackEntry stack[kStackSize];
    WideStackEntry* sp = stack;
    const WideNode<N>* nodes = bvh.nodes.data();
    F tfar_v(node_tfar(tfar));
    std::uint32_t cur = root;
    bool found = false;
    for (;;) {
        while (!wide_child::is_leaf(cur)) {
            count.node();
            const WideNode<N>& node = nodes[cur];
            F entry;
            std::uint32_t bits = node_hits<Test>(node, nr, tfar_v, entry);
            if (bits == 0) goto pop;
            {
                // One child: descend. Two: push the farther. More: push
                // all, sort the pushed entries so the nearest is on top.
                const int i0 = std::countr_zero(bits);
                bits &= bits - 1;
                if (bits == 0) {
                    cur = node.child[i0];
                    continue;
                }
                if constexpr (AnyHit) {
                    // Occlusion needs no order: push the rest as they come.
                    cur = node.child[i0];
                    for (; bits != 0; bits &= bits - 1) *sp++ = {node.child[std::countr_zero(bits)], 0.0f};
                    continue;
                }
                alignas(64) float dist[N];
                entry.store_aligned(dist);
                const int i1 = std::countr_zero(bits);
                bits &= bits - 1;
                if (bits == 0) {
                    const bool first_near = dist[i0] <= dist[i1];
                    const int near = first_near ? i0 : i1, far = first_near ? i1 : i0;
                    *sp++ = {node.child[far], dist[far]};
                    cur = node.child[near];
                    continue;
                }
                WideStackEntry* base = sp;
                *sp++ = {node.child[i0], dist[i0]};
                *sp++ = {node.child[i1], dist[i1]};
                for (; bits != 0; bits &= bits - 1) {
                    const int i = std::countr_zero(bits);
                    *sp++ = {node.child[i], dist[i]};
                }
                // Insertion sort, decreasing distance towards the top.
                for (WideStackEntry* a = base + 1; a < sp; ++a) {
                    const WideStackEntry e = *a;
                    WideStackEntry* b = a;
                    for (; b > base && (b - 1)->dist < e.dist; --b) *b = *(b - 1);
                    *b = e;
                }
                cur = (--sp)->node;
            }
        }
        if (intersect_leaf<TM, AnyHit, ByPrim, Kinds>(bvh, sphere_method, cur, lr, by_prim, tfar, hit, count, cache)) {
            found = true;
            if constexpr (AnyHit) return true;
            tfar_v = F(node_tfar(tfar));
        }
    pop:
        for (;;) {
            if (sp == stack) return found;
            --sp;
            if (AnyHit || sp->dist <= node_tfar(tfar)) break;
        }
        cur = sp->node;
    }
}

/// Closest hit (AnyHit = false: `hit` gets the nearest, the return value
/// says whether there is one) or any hit (returns true at the first) of one
/// ray in [tnear, tfar], with the node test variants `slabs`, `rcp` (see
/// make_node_ray); ByPrim (--precision double) tests leaves through `isect`.
template <int N, int M, TriangleMethod TM, NodeTest Test, bool AnyHit, bool ByPrim = false,
          class Count = NoTraversalCounts, class Kinds = PrimKinds>
bool trace_wide(const WideBvh<N, M>& bvh, SphereMethod sphere_method, const Rayf& ray, Hitf& hit,
                SlabMethod slabs = SlabMethod::Robust, RcpMethod rcp = RcpMethod::Exact,
                const PrimitiveIntersector<float>* isect = nullptr, Count count = {}) {
    if (bvh.nodes.empty()) return false;
    float tfar = ray.tfar;
    const NodeRay<N> nr = make_node_ray<Test, N>(ray, slabs, rcp);
    if constexpr (ByPrim) {
        const PrimLeafRay p{isect, ray};
        return trace_wide_subtree<N, M, TM, Test, AnyHit, true, Count, Kinds>(bvh, sphere_method, 0, nr,
                                                                              LeafRay<vfloat<M>>{}, tfar, hit, &p, count);
    } else {
        return trace_wide_subtree<N, M, TM, Test, AnyHit, false, Count, Kinds>(
            bvh, sphere_method, 0, nr, make_leaf_ray<vfloat<M>>(ray, TM), tfar, hit, nullptr, count);
    }
}

}  // namespace raypack
