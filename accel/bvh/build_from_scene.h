#pragma once
// The scene-facing side of the BVH builders: primitive boxes from the scene,
// the builder and its settings from the AccelConfig, and the clipping of
// primitives for spatial splits. The builders themselves see only boxes.
#include "accel/accel.h"
#include "accel/bvh/bvh2.h"

namespace raypack {

/// BVH2 over every primitive of `scene`, built by config.builder. Throws
/// std::invalid_argument for an unknown builder.
Bvh2 build_scene_bvh2(const Scene& scene, const AccelConfig& config);

/// Bounds of the parts of a truncated cone (NFF `c`, radii >= 0) on either
/// side of the plane `axis` = `position`, each within `box` (the reference's
/// current box); an empty part comes back empty. Conservative: every point
/// of the cone's surface inside `box` lies in the part of its side.
void split_cone(const Vec3f& base, float base_radius, const Vec3f& apex, float apex_radius, const Box3f& box,
                int axis, float position, Box3f& left, Box3f& right);

}  // namespace raypack
