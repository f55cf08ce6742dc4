#pragma once
// What shading needs to know about a hit: position, normals, material.
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

struct Surface {
    Vec3f point;
    Vec3f geometric_normal;  ///< unit, the primitive's own orientation (outward for spheres and cones)
    Vec3f shading_normal;    ///< unit, interpolated for triangles with vertex normals
    std::uint32_t material = 0;
};

/// Surface at a found hit of `ray`.
Surface surface_at(const Scene& scene, const Rayf& ray, const Hitf& hit);

}  // namespace raypack
