#include "accel/bvh/bvh2_packet.h"

#include <bit>

#include "accel/bvh/bvh2_traversal.h"

#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "kernels/aabb.h"
#include "kernels/ray_packet.h"

namespace raypack {
namespace {

/// Fewer active lanes than this at a node, and each finishes the subtree on
/// its own (Benthin, Wald, Woop, Ernst & Mark, "Combining Single and Packet-Ray
/// Tracing for Arbitrary Ray Distributions on the Intel MIC Architecture",
/// TVCG 2012). A binary node costs a packet one box test for all lanes, so
/// only a lone lane gains: measured at K = 16, one thread, 512 x 512, a
/// switch below 2 lanes gave teapot diffuse rays +8% and bunny camera rays
/// +-0, below 3 lanes +9% and -11%, below 6 lanes (the wide BVHs' point)
/// -25% on the bunny.
template <int K>
inline constexpr int kSwitchBelow = 2;

/// The lanes of `lanes` trace the subtree under `root` one by one, from the
/// packet's current state; their hits (and tfar) go back into the packet.
template <int K, bool AnyHit, SlabMethod Slabs>
void finish_lanes_alone(const Bvh2& bvh, const PrimitiveIntersector<float>& single, std::uint32_t root,
                        std::uint32_t lanes, RayPacket<K>& ray, HitPacket<K>& hit, vmask<K>& valid,
                        vmask<K>& occluded) {
    using F = vfloat<K>;
    alignas(64) float ox[K], oy[K], oz[K], dx[K], dy[K], dz[K], tn[K], tf[K], ht[K], hu[K], hv[K];
    ray.org.x.store_aligned(ox), ray.org.y.store_aligned(oy), ray.org.z.store_aligned(oz);
    ray.dir.x.store_aligned(dx), ray.dir.y.store_aligned(dy), ray.dir.z.store_aligned(dz);
    ray.tnear.store_aligned(tn), ray.tfar.store_aligned(tf);
    hit.t.store_aligned(ht), hit.u.store_aligned(hu), hit.v.store_aligned(hv);
    std::uint32_t stopped = 0;
    for (; lanes != 0; lanes &= lanes - 1) {
        const int l = std::countr_zero(lanes);
        Rayf r;
        r.org = {ox[l], oy[l], oz[l]}, r.dir = {dx[l], dy[l], dz[l]}, r.tnear = tn[l], r.tfar = tf[l];
        Hitf h{ht[l], hit.prim[l], hu[l], hv[l]};
        if (!trace_bvh2_subtree<AnyHit, Slabs>(bvh, single, root, r, h)) continue;
        ht[l] = h.t, hit.prim[l] = h.prim, hu[l] = h.u, hv[l] = h.v, tf[l] = r.tfar;
        stopped |= 1u << l;
    }
    hit.t = F::load_aligned(ht), hit.u = F::load_aligned(hu), hit.v = F::load_aligned(hv);
    ray.tfar = F::load_aligned(tf);
    if constexpr (AnyHit) {
        alignas(64) float flag[K];
        for (int l = 0; l < K; ++l) flag[l] = (stopped >> l) & 1u ? 1.0f : 0.0f;
        const vmask<K> m = F::load_aligned(flag) != F(0.0f);
        occluded = occluded | m;
        valid = valid & !m;
    }
}

/// Slabs: the box test `--slabs` names, lane for lane the single ray's
/// (bvh2_traversal.h), on the reciprocal load_packet computed per ray.
template <int K, bool AnyHit, SlabMethod Slabs>
void trace_packet(const Bvh2& bvh, const PacketPrimitiveIntersector<vfloat<K>>& isect,
                  const PrimitiveIntersector<float>& single, RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid,
                  vmask<K>& occluded) {
    using F = vfloat<K>;
    using M = vmask<K>;
    const Bvh2Node* nodes = bvh.nodes.data();
    SlabRay<F> slab = make_slab_ray(ray.org, ray.rdir, ray.tnear, ray.tfar);
    auto box_test = [&](const M& active, std::uint32_t n, F& entry) {
        const Box3f& b = nodes[n].box;
        return intersect_box<Slabs, F>(active, slab, splat<F>(b.lo), splat<F>(b.hi), entry);
    };
    F entry;
    M active = box_test(valid, 0, entry);
    if (none(active)) return;
    std::uint32_t stack[kBvhMaxDepth + 1];
    int sp = 0;
    std::uint32_t current = 0;
    for (;;) {
        const Bvh2Node& node = nodes[current];
        if (const std::uint32_t lanes = mask_bits(active); std::popcount(lanes) < kSwitchBelow<K>) {
            finish_lanes_alone<K, AnyHit, Slabs>(bvh, single, current, lanes, ray, hit, valid, occluded);
            slab.tfar = ray.tfar;
            if constexpr (AnyHit)
                if (none(valid)) return;
        } else if (node.is_leaf()) {
            for (std::uint32_t k = node.first; k < node.first + node.count && any(active); ++k) {
                const M m = isect.intersect(active, ray, hit, bvh.prim_index[k]);
                if constexpr (AnyHit) {
                    occluded = occluded | m;
                    active = active & !m;
                    valid = valid & !m;
                }
            }
            slab.tfar = ray.tfar;
            if constexpr (AnyHit)
                if (none(valid)) return;
        } else {
            const std::uint32_t left = current + 1, right = node.first;
            F entry_left, entry_right;
            const M hit_left = box_test(active, left, entry_left);
            const M hit_right = box_test(active, right, entry_right);
            const bool any_left = any(hit_left), any_right = any(hit_right);
            if (any_left && any_right) {
                // Order by the first ray that meets both children.
                const std::uint32_t both = mask_bits(hit_left & hit_right);
                bool left_first = true;
                if (both) {
                    const int l = std::countr_zero(both);
                    left_first = lane(entry_left, l) <= lane(entry_right, l);
                } else {
                    left_first = std::countr_zero(mask_bits(hit_left)) <= std::countr_zero(mask_bits(hit_right));
                }
                stack[sp++] = left_first ? right : left;
                current = left_first ? left : right;
                active = left_first ? hit_left : hit_right;
                continue;
            }
            if (any_left || any_right) {
                current = any_left ? left : right;
                active = any_left ? hit_left : hit_right;
                continue;
            }
        }
        // Pop the next node some ray still reaches before its closest hit.
        for (;;) {
            if (sp == 0) return;
            current = stack[--sp];
            active = box_test(valid, current, entry);
            if (any(active)) break;
        }
    }
}

}  // namespace

template <int K, bool AnyHit>
void bvh2_trace_packets(const Bvh2& bvh, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                        std::span<Hitf> hits) {
    using F = vfloat<K>;
    if (bvh.nodes.empty()) {
        for (auto& h : hits) h = Hitf{};
        return;
    }
    const PacketPrimitiveIntersector<F> isect{&scene, kernels};
    const PrimitiveIntersector<float> single{&scene, kernels};
    auto run = [&]<SlabMethod Slabs>() {
        trace_in_packets<K, AnyHit>(rays, hits, kernels.rcp, [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid,
                                                                 vmask<K>& occluded) {
            trace_packet<K, AnyHit, Slabs>(bvh, isect, single, ray, hit, valid, occluded);
        });
    };
    if (kernels.slabs == SlabMethod::Plain) return run.template operator()<SlabMethod::Plain>();
    run.template operator()<SlabMethod::Robust>();
}

#if defined(__SSE4_2__)
template void bvh2_trace_packets<4, false>(const Bvh2&, const Scene&, KernelChoice, std::span<const Rayf>,
                                              std::span<Hitf>);
template void bvh2_trace_packets<4, true>(const Bvh2&, const Scene&, KernelChoice, std::span<const Rayf>,
                                              std::span<Hitf>);
#endif
#if defined(__AVX2__)
template void bvh2_trace_packets<8, false>(const Bvh2&, const Scene&, KernelChoice, std::span<const Rayf>,
                                              std::span<Hitf>);
template void bvh2_trace_packets<8, true>(const Bvh2&, const Scene&, KernelChoice, std::span<const Rayf>,
                                              std::span<Hitf>);
#endif
#if defined(__AVX512BW__)
template void bvh2_trace_packets<16, false>(const Bvh2&, const Scene&, KernelChoice, std::span<const Rayf>,
                                              std::span<Hitf>);
template void bvh2_trace_packets<16, true>(const Bvh2&, const Scene&, KernelChoice, std::span<const Rayf>,
                                              std::span<Hitf>);
#endif

}  // namespace raypack
