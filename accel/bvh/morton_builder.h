#pragma once
// Linear BVH from Morton codes (Lauterbach et al., "Fast BVH Construction on
// GPUs", Eurographics 2009; Karras, "Maximizing Parallelism in the
// Construction of BVHs, Octrees, and k-d Trees", HPG 2012): 30-bit codes of
// the box centres in the centroid bounds, a radix sort, then each node splits
// at the highest bit in which its first and last codes differ. The fastest
// build and the worst SAH; leaves hold at most max_leaf_size primitives.
#include <span>

#include "accel/bvh/build_config.h"
#include "accel/bvh/bvh2.h"

namespace raypack {

Bvh2 build_morton(std::span<const Box3f> boxes, const BvhBuildConfig& config);

}  // namespace raypack
