#pragma once
// The scene-facing side of the BVH builders: primitive boxes and centres
// from the scene, builder settings from the AccelConfig. The builders
// themselves see only boxes and centres.
#include "accel/accel.h"
#include "accel/bvh/bvh2.h"

namespace raypack {

/// Binned-SAH BVH2 over every primitive of `scene`.
Bvh2 build_scene_bvh2(const Scene& scene, const AccelConfig& config);

}  // namespace raypack
