#include "accel/bvh/bvh2_packet.h"

#include <bit>

#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "kernels/aabb.h"
#include "kernels/ray_packet.h"

namespace raypack {
namespace {

template <int K, bool AnyHit>
void trace_packet(const Bvh2& bvh, const PacketPrimitiveIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
                  HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
    using F = vfloat<K>;
    using M = vmask<K>;
    const Bvh2Node* nodes = bvh.nodes.data();
    SlabRay<F> slab = make_slab_ray(ray.org, ray.rdir, ray.tnear, ray.tfar);
    auto box_test = [&](const M& active, std::uint32_t n, F& entry) {
        const Box3f& b = nodes[n].box;
        return intersect_box<SlabMethod::Robust, F>(active, slab, splat<F>(b.lo), splat<F>(b.hi), entry);
    };
    F entry;
    M active = box_test(valid, 0, entry);
    if (none(active)) return;
    std::uint32_t stack[kBvhMaxDepth + 1];
    int sp = 0;
    std::uint32_t current = 0;
    for (;;) {
        const Bvh2Node& node = nodes[current];
        if (node.is_leaf()) {
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
    trace_in_packets<K, AnyHit>(rays, hits, [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid,
                                                vmask<K>& occluded) {
        trace_packet<K, AnyHit>(bvh, isect, ray, hit, valid, occluded);
    });
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
