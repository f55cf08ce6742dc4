#pragma once
// Packet traversal of a k-d tree: K rays walk the tree together, each lane
// with its own [tmin, tmax] interval; a child is visited when any active
// lane's interval reaches it (a plain masked form of Wald's packet
// traversal, "Realtime Ray Tracing and Interactive Global Illumination",
// PhD thesis 2004, sec. 7), and leaves test only the lanes that reached them.
// Packets of rays from one point walk in groups, each packet bounded by
// intervals (Reshetov, Soupikov & Hurley 2005).
#include <cstdint>
#include <span>

#include "accel/kdtree/kdtree.h"
#include "accel/primitive_intersector.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

/// Packets that walk the tree as one group when their rays leave one point
/// (kdtree_packet.cpp, trace_group).
inline constexpr int kKdGroupPackets = 16;

/// Closest hits (AnyHit = false) or occlusion (AnyHit = true, hits[i].prim
/// = 0 where occluded) of `rays` in packets of K; with `groups`, packets of
/// rays from one point (pinhole camera rays) walk the tree kKdGroupPackets
/// at a time, with the same answers. Defined for the K that are compiled in
/// (see kWidthCompiled).
template <int K, bool AnyHit>
void kdtree_trace_packets(const KdTree& tree, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                          std::span<Hitf> hits, bool groups = true);

}  // namespace raypack
