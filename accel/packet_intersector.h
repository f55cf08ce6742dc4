#pragma once
// Intersects one scene primitive with the lanes of a ray packet: the leaf
// step of every packet traversal. Structures never look at primitive kinds.
#include <bit>
#include <cstdint>
#include <type_traits>

#include "accel/primitive_intersector.h"
#include "accel/prims/prim_kinds.h"
#include "accel/prims/triangle_edges.h"
#include "kernels/ray_packet.h"
#include "scene/scene.h"

namespace raypack {

/// TriangleRecords: triangles are tested from Moeller's records
/// (`triangle_edges`, accel/prims/triangle_edges.h) where there are some,
/// else from their vertices. A compile-time choice, because the choice
/// itself costs: the k-d tree's group walk ran 7-12% slower with the
/// run-time test in its leaf loop even with no records (GCC compiled the
/// loop worse), and 2-4% slower with them, while the octree's walks gained
/// 3-10% and the grid's 2-5% (Zen 5, camera rays; docs/structures.md).
template <class F, bool TriangleRecords = false>
struct PacketPrimitiveIntersector {
    const Scene* scene;
    KernelChoice kernels;
    /// Moeller's records of the scene's triangles (TriangleEdgeTable), or
    /// null; read only with TriangleRecords.
    const TriangleEdgeRecord* triangle_edges = nullptr;

    /// Lanes of `valid` that hit primitive `prim` within [tnear, tfar]:
    /// records the hit in those lanes of `hit` and shrinks their tfar.
    /// LowestOnTies: a lane whose hit so far lies at exactly the same t on a
    /// primitive of lower number keeps it (the tie rule of the walks whose
    /// lanes test primitives in another order than their single rays,
    /// accel/packet_ties.h); checked before the hit is recorded, so the
    /// common case pays one compare.
    template <bool LowestOnTies = false>
    RAYPACK_INLINE mask_of<F> intersect(mask_of<F> valid, RayLanes<F>& ray, HitLanes<F>& hit,
                                        std::uint32_t prim) const {
        if (kernels.precision == Precision::Double) return intersect_lanes_in_double(valid, ray, hit, prim);
        const PrimRef ref = scene->prims[prim];
        F t, u(0.0f), v(0.0f);
        std::uint32_t ids[lanes_of<F>];
        bool named = false;
        mask_of<F> m = PrimKinds::dispatch(ref.kind, [&]<class Kind>() RAYPACK_INLINE_LAMBDA {
            if constexpr (TriangleRecords && std::is_same_v<Kind, TrianglePrims>)
                if (triangle_edges)
                    return intersect_triangle_record<F>(triangle_edges[ref.index], valid, ray.org, ray.dir,
                                                        ray.tnear, ray.tfar, t, u, v);
            if constexpr (names_hits<Kind>) {
                named = true;
                return Kind::template intersect<F>(*scene, ref.index, kernels, valid, ray, t, u, v, ids);
            } else {
                return Kind::template intersect<F>(*scene, ref.index, kernels, valid, ray, t, u, v);
            }
        });
        if (none(m)) return m;
        if constexpr (LowestOnTies) {
            // Lanes at the same t on another primitive (a primitive met again
            // in a later leaf ties with itself, often: filtered here, not in
            // the out-of-line call).
            std::uint32_t other = 0;
            for (std::uint32_t b = mask_bits(m & (t == hit.t)); b != 0; b &= b - 1) {
                const int l = std::countr_zero(b);
                other |= hit.prim[l] != (named ? ids[l] : prim) ? 1u << l : 0u;
            }
            if (other != 0) [[unlikely]] {
                m = m & !lower_already(other, hit, named ? ids : nullptr, prim);
                if (none(m)) return m;
            }
        }
        hit.t = select(m, t, hit.t);
        hit.u = select(m, u, hit.u);
        hit.v = select(m, v, hit.v);
        ray.tfar = select(m, t, ray.tfar);
        if constexpr (std::is_floating_point_v<F>) {
            hit.prim[0] = named ? ids[0] : prim;
        } else {
            // The primitive numbers blended as float bit patterns (a blend
            // moves bits, it does no arithmetic; the vector loads and stores
            // may alias): a lane-by-lane loop here cost mispredicted
            // branches on every hit.
            float* prims = reinterpret_cast<float*>(hit.prim);
            const F numbers = named ? F::load_unaligned(reinterpret_cast<const float*>(ids))
                                    : F(std::bit_cast<float>(prim));
            select(m, numbers, F::load_unaligned(prims)).store_unaligned(prims);
        }
        return m;
    }

private:
    /// The lanes of `bits` whose hit so far is on a primitive numbered below
    /// this one's (ids: per lane, or null for `prim` in every lane).
    [[gnu::noinline, gnu::cold]] static mask_of<F> lower_already(std::uint32_t bits, const HitLanes<F>& hit,
                                                                 const std::uint32_t* ids, std::uint32_t prim) {
        constexpr int K = lanes_of<F>;
        alignas(64) float lower[K];
        for (int l = 0; l < K; ++l)
            lower[l] = ((bits >> l) & 1u) && hit.prim[l] < (ids ? ids[l] : prim) ? 1.0f : 0.0f;
        return load_lanes<F>(lower) != F(0.0f);
    }

    /// --precision double: the active lanes one by one through the scalar
    /// double test (there is no double packet kernel; double is the
    /// reference, not the fast path).
    __attribute__((noinline)) mask_of<F> intersect_lanes_in_double(mask_of<F> valid, RayLanes<F>& ray,
                                                                   HitLanes<F>& hit, std::uint32_t prim) const {
        constexpr int K = lanes_of<F>;
        alignas(64) float ox[K], oy[K], oz[K], dx[K], dy[K], dz[K], tn[K], tf[K], ht[K], hu[K], hv[K], hitf[K];
        store_lanes(ox, ray.org.x), store_lanes(oy, ray.org.y), store_lanes(oz, ray.org.z);
        store_lanes(dx, ray.dir.x), store_lanes(dy, ray.dir.y), store_lanes(dz, ray.dir.z);
        store_lanes(tn, ray.tnear), store_lanes(tf, ray.tfar);
        store_lanes(ht, hit.t), store_lanes(hu, hit.u), store_lanes(hv, hit.v);
        const PrimitiveIntersector<float> single{scene, kernels};
        for (int l = 0; l < K; ++l) {
            hitf[l] = 0.0f;
            if (!((mask_bits(valid) >> l) & 1u)) continue;
            Rayf r;
            r.org = {ox[l], oy[l], oz[l]}, r.dir = {dx[l], dy[l], dz[l]}, r.tnear = tn[l], r.tfar = tf[l];
            Hitf h;
            if (!single.intersect(prim, r, h)) continue;
            ht[l] = h.t, hu[l] = h.u, hv[l] = h.v, tf[l] = r.tfar, hit.prim[l] = h.prim, hitf[l] = 1.0f;
        }
        hit.t = load_lanes<F>(ht), hit.u = load_lanes<F>(hu), hit.v = load_lanes<F>(hv);
        ray.tfar = load_lanes<F>(tf);
        return load_lanes<F>(hitf) != F(0.0f);
    }
};

/// The intersector of the walks that read triangle records (octree, grids).
template <class F>
using PacketRecordIntersector = PacketPrimitiveIntersector<F, true>;

}  // namespace raypack
