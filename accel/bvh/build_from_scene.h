#pragma once
// The scene-facing side of the BVH builders: primitive boxes from the scene,
// the builder and its settings from the AccelConfig, and exact clipping of
// triangles for spatial splits. The builders themselves see only boxes.
#include "accel/accel.h"
#include "accel/bvh/bvh2.h"

namespace raypack {

/// BVH2 over every primitive of `scene`, built by config.builder. Throws
/// std::invalid_argument for an unknown builder.
Bvh2 build_scene_bvh2(const Scene& scene, const AccelConfig& config);

}  // namespace raypack
