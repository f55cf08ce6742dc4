#pragma once
// BVH4 and BVH8: the binned-SAH BVH2 collapsed into N-wide nodes with SoA
// child boxes and SoA leaf blocks of M primitives, traced one ray at a time
// with SIMD node tests (accel/bvh/wide_traversal.h).
#include "accel/accel.h"
#include "accel/bvh/collapse.h"
#include "accel/bvh/wide_packet.h"
#include "accel/bvh/wide_traversal.h"

namespace raypack {

template <int N, int M, NodeTest Test = NodeTest::Ordered>
class WideBvhAccel final : public Accel {
public:
    /// Builds over every primitive of `scene` (which must outlive this).
    /// `collapse` overrides the leaf costs and size the config implies.
    WideBvhAccel(const Scene& scene, const AccelConfig& config);
    WideBvhAccel(const Scene& scene, const AccelConfig& config, const CollapseConfig& collapse);
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    bool count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits, TraversalCounts& counts) const override;  // wide_counting.cpp
    const WideBvh<N, M>& bvh() const { return bvh_; }

    /// Packets of 4, 8, 16 (as compiled in) for the Ordered node test and
    /// blocks of 8 (accel/bvh/wide_packet.h), whatever the kernel variants;
    /// other node tests and block sizes trace single rays.
    bool supports_packet(int width) const override;
    void intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    /// Streams where kWideStreamCompiled, for the Ordered test and blocks of 8.
    bool supports_stream() const override { return kPackets && kWideStreamCompiled; }
    void intersect_stream(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded_stream(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    /// When packets of `width` fall back to single rays (for measurements and tests).
    void set_packet_config(int width, const WidePacketConfig& config);
    WidePacketConfig packet_config(int width) const;

    /// The collapse settings a config implies (N-wide node and M-wide block costs).
    static CollapseConfig collapse_config(const AccelConfig& config);

private:
    template <bool AnyHit, class Out>
    void trace(std::span<const Rayf> rays, Out&& out) const;

    static constexpr bool kPackets = M == 8 && Test == NodeTest::Ordered;
    const Scene* scene_;  ///< --precision double tests leaves' primitives by id
    KernelChoice kernels_;
    WidePacketConfig packet_config_[3] = {default_wide_packet_config(N, 4), default_wide_packet_config(N, 8),
                                          default_wide_packet_config(N, 16)};  ///< K = 4, 8, 16
    WideBvh<N, M> bvh_;
};

/// The configurations `--accel bvh4` and `--accel bvh8` run: leaf blocks of
/// 8 (one AVX2 vector) were faster than blocks of 4 for both widths on 9 of
/// the 10 scene and ray kinds measured (balls, mount, tetra, teapot, bunny;
/// camera and shadow rays).
#if defined(__AVX2__)
using Bvh4Accel = WideBvhAccel<4, 8>;
using Bvh8Accel = WideBvhAccel<8, 8>;
#elif defined(__SSE4_2__)
using Bvh4Accel = WideBvhAccel<4, 4>;
#endif

}  // namespace raypack
