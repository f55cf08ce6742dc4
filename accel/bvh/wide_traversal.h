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

namespace raypack {

/// Stack entries: a child and its entry distance, so that a pop can skip
/// nodes entered beyond the closest hit found since the push.
struct WideStackEntry {
    std::uint32_t node;
    float dist;
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

/// Tests a run of blocks of one kind; true if something was hit (any hit:
/// stops at the first).
template <TriangleMethod TM, bool AnyHit, int M>
RAYPACK_INLINE bool intersect_run(const TriangleBlock<M>* b, std::uint32_t count, SphereMethod,
                                  const LeafRay<vfloat<M>>& r, float& tfar, Hitf& hit) {
    using F = vfloat<M>;
    bool found = false;
    for (; count != 0; --count, ++b) {
        F t(0.0f), u(0.0f), v(0.0f);  // set by the kernel on hit lanes only
        const std::uint32_t bits = mask_bits(intersect_block<TM, F, M>(*b, r, F(tfar), t, u, v));
        if (bits == 0) continue;
        if constexpr (AnyHit) return true;
        found = true;
        record_nearest(bits, t, u, v, b->prim, tfar, hit);
    }
    return found;
}

template <TriangleMethod TM, bool AnyHit, int M>
RAYPACK_INLINE bool intersect_run(const SphereBlock<M>* b, std::uint32_t count, SphereMethod method,
                                  const LeafRay<vfloat<M>>& r, float& tfar, Hitf& hit) {
    using F = vfloat<M>;
    bool found = false;
    for (; count != 0; --count, ++b) {
        F t(0.0f);
        const std::uint32_t bits = mask_bits(intersect_block<F, M>(*b, method, r, F(tfar), t));
        if (bits == 0) continue;
        if constexpr (AnyHit) return true;
        found = true;
        record_nearest(bits, t, F(0.0f), F(0.0f), b->prim, tfar, hit);
    }
    return found;
}

template <TriangleMethod TM, bool AnyHit, int M>
RAYPACK_INLINE bool intersect_run(const ConeBlock<M>* b, std::uint32_t count, SphereMethod,
                                  const LeafRay<vfloat<M>>& r, float& tfar, Hitf& hit) {
    using F = vfloat<M>;
    bool found = false;
    for (; count != 0; --count, ++b) {
        F t(0.0f), s(0.0f);
        const std::uint32_t bits = mask_bits(intersect_block<F, M>(*b, r, F(tfar), t, s));
        if (bits == 0) continue;
        if constexpr (AnyHit) return true;
        found = true;
        record_nearest(bits, t, s, F(0.0f), b->prim, tfar, hit);
    }
    return found;
}

/// Tests the blocks of one leaf; true if something was hit.
template <TriangleMethod TM, bool AnyHit, int N, int M>
RAYPACK_INLINE bool intersect_leaf(const WideBvh<N, M>& bvh, SphereMethod sm, std::uint32_t code,
                                   const LeafRay<vfloat<M>>& r, float& tfar, Hitf& hit) {
    const std::uint32_t first = wide_child::first(code), count = wide_child::blocks(code);
    switch (wide_child::kind(code)) {
        case LeafKind::Triangle:
            return intersect_run<TM, AnyHit>(bvh.triangles.data() + first, count, sm, r, tfar, hit);
        case LeafKind::Sphere:
            return intersect_run<TM, AnyHit>(bvh.spheres.data() + first, count, sm, r, tfar, hit);
        case LeafKind::Cone:
            return intersect_run<TM, AnyHit>(bvh.cones.data() + first, count, sm, r, tfar, hit);
        case LeafKind::Mixed: break;
    }
    const MixedLeaf& m = bvh.mixed[first];
    constexpr int tri = int(LeafKind::Triangle), sph = int(LeafKind::Sphere), cone = int(LeafKind::Cone);
    bool found = intersect_run<TM, AnyHit>(bvh.triangles.data() + m.first[tri], m.count[tri], sm, r, tfar, hit);
    if (AnyHit && found) return true;
    found |= intersect_run<TM, AnyHit>(bvh.spheres.data() + m.first[sph], m.count[sph], sm, r, tfar, hit);
    if (AnyHit && found) return true;
    found |= intersect_run<TM, AnyHit>(bvh.cones.data() + m.first[cone], m.count[cone], sm, r, tfar, hit);
    return found;
}

/// --precision double: what a leaf needs to test its blocks' primitives one
/// by one, by id, through PrimitiveIntersector<float> (which runs them in
/// double) instead of the float block kernels.
struct PrimLeafRay {
    const PrimitiveIntersector<float>* isect;
    Rayf ray;  ///< tfar is replaced by the current closest hit at each test
};

template <bool AnyHit, class Block>
RAYPACK_INLINE bool intersect_run_by_prim(const Block* b, std::uint32_t count, const PrimLeafRay& p, float& tfar,
                                          Hitf& hit) {
    constexpr int M = int(sizeof(b->prim) / sizeof(b->prim[0]));
    bool found = false;
    for (; count != 0; --count, ++b) {
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

/// intersect_leaf for --precision double.
template <bool AnyHit, int N, int M>
inline bool intersect_leaf_by_prim(const WideBvh<N, M>& bvh, std::uint32_t code, const PrimLeafRay& p, float& tfar,
                                   Hitf& hit) {
    const std::uint32_t first = wide_child::first(code), count = wide_child::blocks(code);
    switch (wide_child::kind(code)) {
        case LeafKind::Triangle: return intersect_run_by_prim<AnyHit>(bvh.triangles.data() + first, count, p, tfar, hit);
        case LeafKind::Sphere: return intersect_run_by_prim<AnyHit>(bvh.spheres.data() + first, count, p, tfar, hit);
        case LeafKind::Cone: return intersect_run_by_prim<AnyHit>(bvh.cones.data() + first, count, p, tfar, hit);
        case LeafKind::Mixed: break;
    }
    const MixedLeaf& m = bvh.mixed[first];
    constexpr int tri = int(LeafKind::Triangle), sph = int(LeafKind::Sphere), cone = int(LeafKind::Cone);
    bool found = intersect_run_by_prim<AnyHit>(bvh.triangles.data() + m.first[tri], m.count[tri], p, tfar, hit);
    if (AnyHit && found) return true;
    found |= intersect_run_by_prim<AnyHit>(bvh.spheres.data() + m.first[sph], m.count[sph], p, tfar, hit);
    if (AnyHit && found) return true;
    found |= intersect_run_by_prim<AnyHit>(bvh.cones.data() + m.first[cone], m.count[cone], p, tfar, hit);
    return found;
}

/// One ray through the subtree under child slot `root` (an inner node or a
/// leaf), with `tfar` the current closest hit distance (shrunk on hits) and
/// `hit` the current closest hit: the traversal of trace_wide, and the
/// single-ray fallback of the packet traversal (accel/bvh/wide_packet.h).
/// True if it found a hit (any hit: returns at the first). ByPrim: leaves
/// go through `by_prim` (--precision double), not the block kernels.
template <int N, int M, TriangleMethod TM, NodeTest Test, bool AnyHit, bool ByPrim = false>
RAYPACK_INLINE bool trace_wide_subtree(const WideBvh<N, M>& bvh, SphereMethod sphere_method, std::uint32_t root,
                                       const NodeRay<N>& nr, const LeafRay<vfloat<M>>& lr, float& tfar, Hitf& hit,
                                       const PrimLeafRay* by_prim = nullptr) {
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
        bool leaf_hit;
        if constexpr (ByPrim) leaf_hit = intersect_leaf_by_prim<AnyHit>(bvh, cur, *by_prim, tfar, hit);
        else leaf_hit = intersect_leaf<TM, AnyHit>(bvh, sphere_method, cur, lr, tfar, hit);
        if (leaf_hit) {
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
template <int N, int M, TriangleMethod TM, NodeTest Test, bool AnyHit, bool ByPrim = false>
bool trace_wide(const WideBvh<N, M>& bvh, SphereMethod sphere_method, const Rayf& ray, Hitf& hit,
                SlabMethod slabs = SlabMethod::Robust, RcpMethod rcp = RcpMethod::Exact,
                const PrimitiveIntersector<float>* isect = nullptr) {
    if (bvh.nodes.empty()) return false;
    float tfar = ray.tfar;
    const NodeRay<N> nr = make_node_ray<Test, N>(ray, slabs, rcp);
    if constexpr (ByPrim) {
        const PrimLeafRay p{isect, ray};
        return trace_wide_subtree<N, M, TM, Test, AnyHit, true>(bvh, sphere_method, 0, nr, LeafRay<vfloat<M>>{}, tfar,
                                                                hit, &p);
    } else {
        return trace_wide_subtree<N, M, TM, Test, AnyHit>(bvh, sphere_method, 0, nr, make_leaf_ray<vfloat<M>>(ray, TM),
                                                          tfar, hit);
    }
}

}  // namespace raypack
