#include "accel/kdtree/kdtree_packet.h"

#include <algorithm>
#include <bit>
#include <limits>

#include "accel/kdtree/kdtree_ray_interval.h"
#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "kernels/ray_packet.h"

namespace raypack {
namespace {

/// Lanes of `tie` hit prim at exactly the t they had before: restore the
/// earlier hit where its primitive number is lower.
template <int K>
void keep_lowest_on_ties(const vmask<K>& tie, const HitPacket<K>& before, HitPacket<K>& hit, std::uint32_t prim) {
    std::uint32_t bits = mask_bits(tie);
    if (!bits) return;
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

// The single-ray traversal of kdtree_accel.cpp lane by lane: the same
// widened planes, so every lane visits at least the leaves its single ray
// would, and the same kernels, so the hits are bit for bit the same. A lane
// is active in a node while tmin <= min(tmax, tfar).
template <int K, bool AnyHit, SlabMethod Slabs>
void trace_packet(const KdTree& tree, const PacketPrimitiveIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
                  HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
    using F = vfloat<K>;
    using M = vmask<K>;
    const F inf(std::numeric_limits<float>::infinity());
    F tmin, tmax;
    const M in_box = kd_ray_interval<F, Slabs>(valid, ray.org, ray.rdir, ray.tnear, ray.tfar, tree.bounds,
                                               tree.margin, tmin, tmax);
    if (none(in_box)) return;
    // Inactive lanes get an empty interval, which stays empty in every child.
    tmin = select(in_box, tmin, inf);
    tmax = select(in_box, tmax, -inf);
    constexpr bool plain = Slabs == SlabMethod::Plain;
    const F margin(plain ? 0.0f : tree.margin);
    const Vec3<F> slack{margin * vabs(ray.rdir.x), margin * vabs(ray.rdir.y), margin * vabs(ray.rdir.z)};
    const Vec3<F> org_rdir{ray.org.x * ray.rdir.x, ray.org.y * ray.rdir.y, ray.org.z * ray.rdir.z};
    const M positive[3] = {ray.rdir.x >= F(0.0f), ray.rdir.y >= F(0.0f), ray.rdir.z >= F(0.0f)};
    const bool double_ties = isect.kernels.precision == Precision::Double;
    const KdNode* nodes = tree.nodes.data();
    struct PendingNode {
        F tmin, tmax;
        std::uint32_t node;
    };
    PendingNode stack[kKdMaxDepth + 1];
    int sp = 0;
    std::uint32_t current = 0;
    for (;;) {
        const KdNode node = nodes[current];
        if (!node.is_leaf()) {
            const int a = node.axis();
            const F t_split = plane_distance<Slabs>(F(node.split()), ray.org[a], ray.rdir[a], org_rdir[a]);
            const F near_end = vmin(tmax, plain ? t_split : t_split + slack[a]);
            const F far_start = vmax(tmin, plain ? t_split : t_split - slack[a]);
            // Per lane, below is the near side where the direction is positive.
            const M pos = positive[a];
            const F below_lo = select(pos, tmin, far_start), below_hi = select(pos, near_end, tmax);
            const F above_lo = select(pos, far_start, tmin), above_hi = select(pos, tmax, near_end);
            const bool any_below = any(below_lo <= below_hi), any_above = any(above_lo <= above_hi);
            if (any_below && any_above) {
                // Front to back for the first active lane.
                const std::uint32_t first = std::countr_zero(mask_bits(tmin <= tmax));
                const bool below_first = (mask_bits(pos) >> first) & 1u;
                if (below_first) {
                    stack[sp++] = {above_lo, above_hi, node.above_child()};
                    current = current + 1, tmin = below_lo, tmax = below_hi;
                } else {
                    stack[sp++] = {below_lo, below_hi, current + 1};
                    current = node.above_child(), tmin = above_lo, tmax = above_hi;
                }
            } else if (any_below) {
                current = current + 1, tmin = below_lo, tmax = below_hi;
            } else {
                current = node.above_child(), tmin = above_lo, tmax = above_hi;
            }
            continue;
        }
        const std::uint32_t count = node.prim_count();
        const std::uint32_t* prims = tree.leaf_prims(nodes[current]);
        M active = tmin <= tmax;
        for (std::uint32_t k = 0; k < count; ++k) {
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
                if (any(m)) keep_lowest_on_ties<K>(m & !farther & (hit.t == before.t), before, hit, prims[k]);
            } else {
                const HitPacket<K> before = hit;
                const M m = isect.intersect(active, ray, hit, prims[k]);
                // Equal t: the lowest primitive number wins, as in the single-ray path.
                if (any(m)) keep_lowest_on_ties<K>(m & (hit.t == before.t), before, hit, prims[k]);
            }
        }
        if constexpr (AnyHit) {
            valid = valid & !occluded;
            if (none(valid)) return;
        }
        // Pop the next node some lane reaches before its closest hit so far.
        for (;;) {
            if (sp == 0) return;
            const PendingNode& t = stack[--sp];
            M live = t.tmin <= vmin(t.tmax, ray.tfar);
            if constexpr (AnyHit) live = live & valid;
            if (any(live)) {
                current = t.node;
                tmin = select(live, t.tmin, inf);
                tmax = select(live, vmin(t.tmax, ray.tfar), -inf);
                break;
            }
        }
    }
}

}  // namespace

template <int K, bool AnyHit>
void kdtree_trace_packets(const KdTree& tree, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                          std::span<Hitf> hits) {
    using F = vfloat<K>;
    const PacketPrimitiveIntersector<F> isect{&scene, kernels};
    // The slab form is chosen once for all packets, rdir once per packet.
    with_slab_form(kernels.slabs, [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
        trace_in_packets<K, AnyHit>(rays, hits, kernels.rcp, [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid,
                                                    vmask<K>& occluded) {
            if (tree.empty()) return;
            trace_packet<K, AnyHit, Slabs>(tree, isect, ray, hit, valid, occluded);
        });
    });
}

#if defined(__SSE4_2__)
template void kdtree_trace_packets<4, false>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
template void kdtree_trace_packets<4, true>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
#endif
#if defined(__AVX2__)
template void kdtree_trace_packets<8, false>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
template void kdtree_trace_packets<8, true>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
#endif
#if defined(__AVX512BW__)
template void kdtree_trace_packets<16, false>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
template void kdtree_trace_packets<16, true>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
#endif

}  // namespace raypack
