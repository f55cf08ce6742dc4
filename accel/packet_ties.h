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

/// One closest-hit test of `prim` on the lanes `active` under the tie rule
/// (PacketPrimitiveIntersector::intersect<true>); returns the lanes it hit.
/// The octree's and the k-d tree's walks use it in float precision. The
/// k-d tree used to compare with a copy of the hits taken before each test
/// (4% fewer instructions on teapot's camera rays, under callgrind); since
/// session 36 this: camera rays 1.04x on gears, tetra and balls, teapot
/// 1.00x, shadow and diffuse 1.00x (Zen 5, K = 16).
template <int K, class Intersector>
RAYPACK_INLINE vmask<K> intersect_keeping_lowest(const Intersector& isect, vmask<K> active, RayPacket<K>& ray,
                                                 HitPacket<K>& hit, std::uint32_t prim) {
    return isect.template intersect<true>(active, ray, hit, prim);
}

}  // namespace raypack
