#pragma once
// Binned SAH construction (Wald, "On fast Construction of SAH-based Bounding
// Volume Hierarchies", IEEE RT 2007), parallel with oneTBB: the large nodes
// near the root bin in parallel over primitive ranges, the subtrees below
// them build as parallel tasks. The tree does not depend on the thread count.
#include <span>

#include "accel/bvh/build_config.h"
#include "accel/bvh/bvh2.h"
#include "accel/bvh/bvh2_finalize.h"

namespace raypack {

/// Builds over boxes[i], i = primitive number; centres are box centres.
Bvh2 build_binned_sah(std::span<const Box3f> boxes, const BvhBuildConfig& config);

}  // namespace raypack
