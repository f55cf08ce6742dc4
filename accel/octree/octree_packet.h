#pragma once
// Packet traversal of the octree: the lanes of a packet whose directions lie
// in one octant walk the tree together in one shared front-to-back order,
// each inner node's children tested with the parametric intervals of
// Revelles et al. (lane-wise), leaves tested for the lanes that reach them;
// and groups of such packets in one walk, each standing for its lanes by
// bounds of their parameters.
#include <cstdint>
#include <span>

#include "accel/octree/octree.h"
#include "accel/primitive_intersector.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

/// Packets of K rays that walk the tree as one group when their rays share a
/// direction octant (octree_packet.cpp, trace_group): one lane of a SIMD
/// register per packet, 16 packets of 16 (camera rays 1.025-1.045x as fast as
/// 8 on the SPD scenes, with the near-parallel packets walking alone,
/// kMaxReciprocalSpread), else 8.
constexpr int octree_group_packets(int K) { return K == 16 ? 16 : 8; }

/// Closest hits (AnyHit = false) or occlusion (AnyHit = true, hits[i].prim
/// = 0 where occluded) of `rays` in packets of K; with `groups`, packets
/// whose rays share a direction octant walk the tree octree_group_packets(K) at a time
/// (octree_packet.cpp, trace_group), with the same answers.
/// `triangle_edges`: the octree's triangle records
/// (accel/prims/triangle_edges.h) or null. Defined for the K that are
/// compiled in (see kWidthCompiled).
template <int K, bool AnyHit>
void octree_trace_packets(const Octree& tree, const Scene& scene, KernelChoice kernels,
                          const TriangleEdgeRecord* triangle_edges, std::span<const Rayf> rays,
                          std::span<Hitf> hits, bool groups = true);

}  // namespace raypack
