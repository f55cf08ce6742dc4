#pragma once
// Full-sweep SAH: every node evaluates the SAH at every position between
// primitives sorted by centre along each axis (MacDonald & Booth 1990; Wald,
// Boulos, Shirley, "Ray Tracing Deformable Scenes using Dynamic BVHs", ACM
// TOG 2007). The three orders are sorted once and kept by stable
// partitioning, so the build is O(N log N). The reference for quality.
#include <span>

#include "accel/bvh/build_config.h"
#include "accel/bvh/bvh2.h"

namespace raypack {

Bvh2 build_sweep_sah(std::span<const Box3f> boxes, const BvhBuildConfig& config);

}  // namespace raypack
