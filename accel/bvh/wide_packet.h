#pragma once
// Packets of K rays through a BVH4 or BVH8 (Wald, Slusallek, Benthin,
// Wagner, "Interactive Rendering with Coherent Ray Tracing", EG 2001, on the
// wide trees of Dammertz et al. 2008), falling back to the single-ray wide
// traversal when few lanes stay active (Benthin, Wald, Woop, Ernst, Mark,
// "Combining Single and Packet-Ray Tracing for Arbitrary Ray Distributions
// on the Intel MIC Architecture", IEEE TVCG 2012), and coherent packets in
// groups that share one walk (accel/bvh/wide_group_traversal.h). The
// templates live in accel/bvh/wide_packet_traversal.h and
// wide_group_traversal.h and are instantiated per tree width in
// wide_packet_bvh4.cpp and wide_packet_bvh8.cpp.
#include <cstdint>
#include <span>

#include "accel/bvh/wide_bvh.h"
#include "accel/primitive_intersector.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

/// How packets walk the tree: together in groups, alone, or as single rays.
struct WidePacketConfig {
    /// At a node (inner or leaf) reached by fewer active lanes than this,
    /// each of those lanes traces the subtree alone with the single-ray
    /// wide traversal (trace_wide_subtree). 0: never; K + 1: always, so the
    /// packet only shares the root.
    int switch_below = 2;
    /// Packets that walk the tree together (accel/bvh/wide_group_traversal.h),
    /// at most kMaxGroupPackets; 1: each packet alone.
    int group_packets = 1;
    static constexpr int kMaxGroupPackets = 16;
    /// Any hit: packets test the primitive that stopped the last occluded
    /// ray first (OccluderCache, accel/bvh/wide_traversal.h); never with
    /// --slabs plain.
    bool occluder_cache = true;
    /// Streams (wide_trace_stream): a node's list of fewer rays than this
    /// finishes its subtree one ray at a time.
    int stream_single_below = 8;
};

/// The default switch point for N-wide trees and packets of K. Measured with
/// raypack_bench --benchmark_filter=switch/ (teapot and mount at 512 x 512,
/// one thread, CPU time): camera rays change by at most 5% anywhere in
/// 0..K/2, best near 2..4; random-direction rays from the camera hits are
/// 20-60% faster at K/4..K/2 than at 0 (never fall back; K = 16 on
/// teapot's BVH8: 7.9 -> 12.6 Mrays/s). K + 1 (every lane alone from the
/// root) halves camera rays' speed.
constexpr int default_wide_switch_below(int n, int k) {
    (void)n;
    return k == 4 ? 2 : k == 8 ? 4 : 6;
}

/// The default configuration: that switch point, and groups of 128 rays
/// (16 packets of 8, 8 of 16; 64 rays for packets of 4). Measured on an
/// AVX2 Zen 3 (docs/embree.md, "Packets that share a walk"): camera rays in
/// 8 x 8 tiles of gears and the bunny 1.25-1.3x faster at 16 packets of 8
/// than alone, tetra and teapot unchanged; renders of teapot and the
/// path-traced bunny about 10% faster; diffuse packets never form a group.
constexpr WidePacketConfig default_wide_packet_config(int n, int k) {
    WidePacketConfig c;
    c.switch_below = default_wide_switch_below(n, k);
    c.group_packets = k == 16 ? 8 : 16;
    return c;
}

/// Closest hits of `rays` in packets of K consecutive rays. Defined for N =
/// 4, 8 with M = 8 and the K that are compiled in (kWidthCompiled). `scene`
/// is the one the tree was built over (--precision double tests leaves'
/// primitives by id).
template <int N, int M, int K>
void wide_trace_packets(const WideBvh<N, M>& bvh, const Scene& scene, KernelChoice kernels,
                        const WidePacketConfig& config, std::span<const Rayf> rays, std::span<Hitf> hits);

/// Occlusion of `rays` in packets of K, the same way: occluded[i] = 1 where
/// occluded. The answers go straight from the lane masks into the bytes (a
/// hit record per ray in between was a tenth of the query's time).
template <int N, int M, int K>
void wide_occluded_packets(const WideBvh<N, M>& bvh, const Scene& scene, KernelChoice kernels,
                           const WidePacketConfig& config, std::span<const Rayf> rays,
                           std::span<std::uint8_t> occluded);

/// Whether this build walks streams: lists of rays are compacted 16 lanes
/// at a time with AVX-512's compress.
#if defined(__AVX512BW__)
inline constexpr bool kWideStreamCompiled = true;
#else
inline constexpr bool kWideStreamCompiled = false;
#endif

/// Closest hits (AnyHit = false, into `hits`) or occlusion (AnyHit = true:
/// occluded[i] = 1 where occluded) of `rays` walked as one stream
/// (accel/bvh/wide_stream_traversal.h): for rays whose neighbours go other
/// ways. Defined for N = 4, 8 with M = 8 where kWideStreamCompiled;
/// --precision double traces packets of 16 instead.
template <int N, int M, bool AnyHit>
void wide_trace_stream(const WideBvh<N, M>& bvh, const Scene& scene, KernelChoice kernels,
                       const WidePacketConfig& config, std::span<const Rayf> rays, std::span<Hitf> hits,
                       std::span<std::uint8_t> occluded);

}  // namespace raypack
