#pragma once
// Packet traversal of a k-d tree: K rays walk the tree together, each lane
// with its own [tmin, tmax] interval; a child is visited when any active
// lane's interval reaches it (a plain masked form of Wald's packet
// traversal, "Realtime Ray Tracing and Interactive Global Illumination",
// PhD thesis 2004, sec. 7), and leaves test only the lanes that reached them.
#include <cstdint>
#include <span>

#include "accel/kdtree/kdtree.h"
#include "accel/primitive_intersector.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

/// Closest hits (AnyHit = false) or occlusion (AnyHit = true, hits[i].prim
/// = 0 where occluded) of `rays` in packets of K. Defined for the K that are
/// compiled in (see kWidthCompiled).
template <int K, bool AnyHit>
void kdtree_trace_packets(const KdTree& tree, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                          std::span<Hitf> hits);

}  // namespace raypack
