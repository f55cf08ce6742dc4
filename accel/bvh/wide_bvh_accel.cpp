#include "accel/bvh/wide_bvh_accel.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "accel/bvh/binned_sah_builder.h"
#include "accel/bvh/build_from_scene.h"
#include "accel/packet_widths.h"

namespace raypack {

template <int N, int M, NodeTest Test>
CollapseConfig WideBvhAccel<N, M, Test>::collapse_config(const AccelConfig& config) {
    CollapseConfig c;
    // The default walks (packets, streams) test a leaf K rays x 1
    // primitive, and pay about three block tests at a wide node: N box
    // tests, the children's order and, in a stream, a list per child.
    // Leaves of up to 3 M: diffuse streams 7-11% faster on gears and the
    // bunny, the rest within noise (docs/structures.md, session 41).
    // config.traversal_cost / intersection_cost keep their meaning as the
    // ratio of the two.
    c.node_cost = 3.0f * config.traversal_cost;
    c.block_cost = config.intersection_cost;
    c.max_leaf_prims = 3 * M;
    c.triangle_layout =
        config.kernels.triangle == TriangleMethod::Moeller ? TriangleLayout::Edges : TriangleLayout::Vertices;
    return c;
}

template <int N, int M, NodeTest Test>
WideBvhAccel<N, M, Test>::WideBvhAccel(const Scene& scene, const AccelConfig& config)
    : WideBvhAccel(scene, config, collapse_config(config)) {}

template <int N, int M, NodeTest Test>
WideBvhAccel<N, M, Test>::WideBvhAccel(const Scene& scene, const AccelConfig& config, const CollapseConfig& collapse)
    : scene_(&scene), kernels_(config.kernels) {
    const Bvh2 binary = build_scene_bvh2(scene, config);
    CollapseConfig cc = collapse;
    cc.triangle_layout = collapse_config(config).triangle_layout;  // must match the kernel that runs
    cc.objects = config.kernels.objects;
    bvh_ = collapse_bvh<N, M>(binary, scene, cc);
    if (config.packet_group > 0)
        for (WidePacketConfig& c : packet_config_) c.group_packets = config.packet_group;
    stats_.name = N == 4 ? "bvh4" : "bvh8";
    stats_.builder = config.builder;
    stats_.nodes = bvh_.nodes.size();
    stats_.leaves = bvh_.leaves;
    stats_.depth = bvh_.depth;
    stats_.bytes = bvh_.bytes();
    stats_.sah_cost = sah_cost(bvh_, config.traversal_cost, config.intersection_cost);
    stats_.primitives = scene.primitive_count();
    stats_.specialisation = specialisation_for(scene, config.kernels);
    if (stats_.primitives) stats_.refs_per_prim = double(binary.prim_index.size()) / double(stats_.primitives);
}

template <int N, int M, NodeTest Test>
template <bool AnyHit, class Out>
void WideBvhAccel<N, M, Test>::trace(std::span<const Rayf> rays, Out&& out) const {
    // Variants chosen once per batch: the triangle kernel and precision by
    // template, slabs and rcp in each ray's setup (make_node_ray).
    const PrimitiveIntersector<float> isect{scene_, kernels_};
    auto run = [&]<TriangleMethod TM, bool ByPrim, class Kinds = PrimKinds>() {
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Hitf hit;
            const bool any = trace_wide<N, M, TM, Test, AnyHit, ByPrim, NoTraversalCounts, Kinds>(
                bvh_, kernels_.sphere, rays[i], hit, kernels_.slabs, kernels_.rcp, &isect);
            out(i, any, hit);
        }
    };
    // Double: the block kernels are not used, so one instantiation serves
    // every triangle method (PrimitiveIntersector runs the chosen one).
    if (kernels_.precision == Precision::Double) return run.template operator()<TriangleMethod::Moeller, true>();
    if (stats_.specialisation == KindSpecialisation::Triangles)
        return run.template operator()<TriangleMethod::Moeller, false, TriangleKinds>();
    switch (kernels_.triangle) {
        case TriangleMethod::Moeller: return run.template operator()<TriangleMethod::Moeller, false>();
        case TriangleMethod::Watertight: return run.template operator()<TriangleMethod::Watertight, false>();
        case TriangleMethod::Plane: return run.template operator()<TriangleMethod::Plane, false>();
    }
}

template <int N, int M, NodeTest Test>
void WideBvhAccel<N, M, Test>::intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const {
    trace<false>(rays, [&](std::size_t i, bool, const Hitf& hit) { hits[i] = hit; });
}

template <int N, int M, NodeTest Test>
void WideBvhAccel<N, M, Test>::occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const {
    trace<true>(rays, [&](std::size_t i, bool any, const Hitf&) { occluded[i] = any ? 1 : 0; });
}

namespace {
int packet_slot(int width) { return width == 4 ? 0 : width == 8 ? 1 : 2; }

/// fn.template operator()<K>() for K = width where the packet walks are
/// compiled for this tree (Compiled: blocks of 8, the ordered node test);
/// elsewhere an std::invalid_argument naming the structure.
template <bool Compiled, class Fn>
void with_tree_packet_width(int width, const std::string& name, Fn&& fn) {
    if constexpr (Compiled) {
        with_packet_width(width, name, fn);
    } else {
        (void)fn;
        throw std::invalid_argument(name + ": packets of " + std::to_string(width) + " are not compiled in");
    }
}
}  // namespace

template <int N, int M, NodeTest Test>
bool WideBvhAccel<N, M, Test>::supports_packet(int width) const {
    return width == 1 || (kPackets && packet_width_compiled(width));
}

template <int N, int M, NodeTest Test>
void WideBvhAccel<N, M, Test>::set_packet_config(int width, const WidePacketConfig& config) {
    packet_config_[packet_slot(width)] = config;
}

template <int N, int M, NodeTest Test>
WidePacketConfig WideBvhAccel<N, M, Test>::packet_config(int width) const {
    return packet_config_[packet_slot(width)];
}

template <int N, int M, NodeTest Test>
void WideBvhAccel<N, M, Test>::intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    if (width == 1 || !supports_packet(width)) return intersect(rays, hits);
    const WidePacketConfig& c = packet_config_[packet_slot(width)];
    with_tree_packet_width<kPackets>(width, stats_.name, [&]<int K>() {
        wide_trace_packets<N, M, K>(bvh_, *scene_, kernels_, c, rays, hits);
    });
}

template <int N, int M, NodeTest Test>
void WideBvhAccel<N, M, Test>::occluded_packets(int width, std::span<const Rayf> rays,
                                                std::span<std::uint8_t> occluded) const {
    if (width == 1 || !supports_packet(width)) return this->occluded(rays, occluded);
    const WidePacketConfig& c = packet_config_[packet_slot(width)];
    with_tree_packet_width<kPackets>(width, stats_.name, [&]<int K>() {
        wide_occluded_packets<N, M, K>(bvh_, *scene_, kernels_, c, rays, occluded);
    });
}

/// Below this many rays a batch goes as packets: too few to fill the lists.
constexpr std::size_t kMinStreamRays = 256;

template <int N, int M, NodeTest Test>
void WideBvhAccel<N, M, Test>::intersect_stream(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    if constexpr (kPackets && kWideStreamCompiled) {
        if (rays.size() >= kMinStreamRays)
            return wide_trace_stream<N, M, false>(bvh_, *scene_, kernels_, packet_config_[2], rays, hits, {});
    }
    intersect_packets(width, rays, hits);
}

template <int N, int M, NodeTest Test>
void WideBvhAccel<N, M, Test>::occluded_stream(int width, std::span<const Rayf> rays,
                                               std::span<std::uint8_t> occluded) const {
    if constexpr (kPackets && kWideStreamCompiled) {
        if (rays.size() >= kMinStreamRays)
            return wide_trace_stream<N, M, true>(bvh_, *scene_, kernels_, packet_config_[2], rays, {}, occluded);
    }
    occluded_packets(width, rays, occluded);
}

#if defined(__SSE4_2__)
template class WideBvhAccel<4, 4>;
#endif
#if defined(__AVX2__)
template class WideBvhAccel<8, 4>;
template class WideBvhAccel<8, 8>;
template class WideBvhAccel<4, 8>;
template class WideBvhAccel<8, 8, NodeTest::Plain>;
template class WideBvhAccel<8, 8, NodeTest::Robust>;
template class WideBvhAccel<4, 8, NodeTest::Plain>;
template class WideBvhAccel<4, 8, NodeTest::Robust>;
#endif

}  // namespace raypack
