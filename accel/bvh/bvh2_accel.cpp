#include "accel/bvh/bvh2_accel.h"

#include <stdexcept>
#include <vector>

#include "accel/bvh/build_from_scene.h"
#include "accel/bvh/bvh2_finalize.h"
#include "accel/bvh/bvh2_packet.h"
#include "accel/bvh/bvh2_traversal.h"
#include "accel/packet_widths.h"
#include "kernels/simd.h"

namespace raypack {

Bvh2Accel::Bvh2Accel(const Scene& scene, const AccelConfig& config) : scene_(&scene), kernels_(config.kernels) {
    bvh_ = build_scene_bvh2(scene, config);
    stats_.name = "bvh2";
    stats_.builder = config.builder;
    stats_.nodes = bvh_.nodes.size();
    stats_.leaves = bvh_.leaves;
    stats_.depth = bvh_.depth;
    stats_.bytes = bvh_.nodes.size() * sizeof(Bvh2Node) + bvh_.prim_index.size() * sizeof(std::uint32_t);
    stats_.sah_cost = sah_cost(bvh_, config.traversal_cost, config.intersection_cost);
    stats_.primitives = scene.primitive_count();
    stats_.refs_per_prim = stats_.primitives ? double(bvh_.prim_index.size()) / double(stats_.primitives) : 1.0;
}

template <bool AnyHit, class Out>
void Bvh2Accel::trace(std::span<const Rayf> rays, Out&& out) const {
    const PrimitiveIntersector<float> isect{scene_, kernels_};
    auto run = [&]<SlabMethod Slabs>() {
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Rayf ray = rays[i];
            Hitf hit;
            const bool found = !bvh_.nodes.empty() && trace_bvh2_subtree<AnyHit, Slabs>(bvh_, isect, 0, ray, hit);
            out(i, found, hit);
        }
    };
    if (kernels_.slabs == SlabMethod::Plain) return run.template operator()<SlabMethod::Plain>();
    run.template operator()<SlabMethod::Robust>();
}

void Bvh2Accel::intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const {
    trace<false>(rays, [&](std::size_t i, bool, const Hitf& hit) { hits[i] = hit; });
}

void Bvh2Accel::occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const {
    trace<true>(rays, [&](std::size_t i, bool found, const Hitf&) { occluded[i] = found ? 1 : 0; });
}

bool Bvh2Accel::supports_packet(int width) const { return packet_width_compiled(width); }

template <bool AnyHit>
void Bvh2Accel::trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    with_packet_width(width, "bvh2", [&]<int K>() {
        bvh2_trace_packets<K, AnyHit>(bvh_, *scene_, kernels_, rays, hits);
    });
}

void Bvh2Accel::intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    if (width == 1) return intersect(rays, hits);
    trace_packets<false>(width, rays, hits);
}

void Bvh2Accel::occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const {
    if (width == 1) return this->occluded(rays, occluded);
    occlusion_in_slices(rays, occluded, [&](std::span<const Rayf> slice, std::span<Hitf> hits) {
        trace_packets<true>(width, slice, hits);
    });
}

}  // namespace raypack
