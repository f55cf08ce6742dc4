#pragma once
// The standard ray sets traced by benchmarks and comparisons.
#include <vector>

#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

/// One ray through each pixel centre, row by row from the top.
std::vector<Rayf> camera_ray_set(const Scene& scene, int width, int height);

/// From each camera-ray hit (found with the reference BVH2) toward the first
/// light, offset off the surface; tfar stops just short of the light. Empty
/// when the scene has no light.
std::vector<Rayf> shadow_ray_set(const Scene& scene, int width, int height);

}  // namespace raypack
