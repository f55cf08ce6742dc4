#pragma once
// Packet traversal of a BVH2 (Wald, Slusallek, Benthin, Wagner, "Interactive
// Rendering with Coherent Ray Tracing", EG 2001): K rays walk the tree
// together, a node is entered when any active ray meets its box, and leaves
// test only the lanes that reached them.
#include <cstdint>
#include <span>

#include "accel/bvh/bvh2.h"
#include "accel/primitive_intersector.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

/// Closest hits (AnyHit = false) or occlusion (AnyHit = true, hits[i].prim
/// = 0 where occluded) of `rays` in packets of K. Defined for the K that are
/// compiled in (see kWidthCompiled).
template <int K, bool AnyHit>
void bvh2_trace_packets(const Bvh2& bvh, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                        std::span<Hitf> hits);

}  // namespace raypack
