#pragma once
// Points on area lights (scene/scene.h AreaLight) for shadow rays: uniform
// by area over the part of the light that can face the shaded point.
#include "kernels/vec3.h"
#include "render/sampler.h"
#include "scene/scene.h"

namespace raypack {

struct LightSample {
    Vec3f point;   ///< on the light's surface
    Vec3f normal;  ///< unit, the emitting side
    /// Density by area of `point`; 1 / pdf_area is the area sampled from.
    float pdf_area = 0;
};

/// A parallelogram is sampled uniformly over its whole area. A sphere is
/// sampled uniformly over the cap that the point `seen_from` can see
/// (cos alpha >= r / d about the axis toward it; the whole sphere when the
/// point is inside), since the rest of the sphere is hidden by the sphere
/// itself.
LightSample sample_area_light(const AreaLight& light, const Vec3f& seen_from, Sample2 u);

/// The density by area with which sample_area_light(light, seen_from, .)
/// picks a point of the region it samples (for multiple importance sampling).
float area_light_pdf(const AreaLight& light, const Vec3f& seen_from);

}  // namespace raypack
