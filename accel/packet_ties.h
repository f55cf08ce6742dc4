#pragma once
// The tie rule of the walks whose lanes may test primitives in another order
// than their single rays (the k-d tree's and the octree's packets and groups
// of packets): of several primitives hit at exactly the same t the lowest
// number wins, which makes a closest hit independent of the visiting order.
// The kernels accept t == tfar, so without it the last one tested would win.
#include <bit>
#include <cstdint>

#include "kernels/ray_packet.h"

namespace raypack {

/// Lanes of `tie` hit prim at exactly the t they had before: restore the
/// earlier hit where its primitive number is lower. Rare, hence out of line:
/// a call on the common path makes every live vector register spill.
template <int K>
[[gnu::noinline, gnu::cold]] void keep_lowest_on_ties(const vmask<K>& tie, const HitPacket<K>& before,
                                                      HitPacket<K>& hit, std::uint32_t prim) {
    std::uint32_t bits = mask_bits(tie);
    // t too: +0 == -0, and the earlier hit keeps its own sign of zero.
    alignas(64) float t[K], u[K], v[K], bt[K], bu[K], bv[K];
    store_lanes(t, hit.t), store_lanes(u, hit.u), store_lanes(v, hit.v);
    store_lanes(bt, before.t), store_lanes(bu, before.u), store_lanes(bv, before.v);
    for (; bits; bits &= bits - 1) {
        const int l = std::countr_zero(bits);
        if (before.prim[l] < prim) hit.prim[l] = before.prim[l], t[l] = bt[l], u[l] = bu[l], v[l] = bv[l];
    }
    hit.t = load_lanes<vfloat<K>>(t);
    hit.u = load_lanes<vfloat<K>>(u);
    hit.v = load_lanes<vfloat<K>>(v);
}

/// Some lane of `tie_bits` had its hit on another primitive than `prim`
/// (a primitive tested again in a later leaf ties with itself, often).
template <int K>
RAYPACK_INLINE bool ties_another_primitive(std::uint32_t tie_bits, const HitPacket<K>& before, std::uint32_t prim) {
    for (; tie_bits; tie_bits &= tie_bits - 1)
        if (before.prim[std::countr_zero(tie_bits)] != prim) return true;
    return false;
}

/// One closest-hit test of `prim` on the lanes `active` under the tie rule
/// (PacketPrimitiveIntersector::intersect<true>); returns the lanes it hit.
/// The octree's walks use it; the k-d tree's leaf test compares with a copy
/// of the hit taken before the test instead (kdtree_packet.cpp), which its
/// group walk ran in 4% fewer instructions (teapot, camera rays), where the
/// octree's packets ran up to 3% faster with this (gears).
template <int K, class Intersector>
RAYPACK_INLINE vmask<K> intersect_keeping_lowest(const Intersector& isect, vmask<K> active, RayPacket<K>& ray,
                                                 HitPacket<K>& hit, std::uint32_t prim) {
    return isect.template intersect<true>(active, ray, hit, prim);
}

}  // namespace raypack
