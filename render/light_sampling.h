#pragma once
// Points on area lights (scene/scene.h AreaLight) for shadow rays: uniform
// by area over the part of the light that can face the shaded point.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "kernels/vec3.h"
#include "render/sampler.h"
#include "render/sampling.h"
#include "render/sin_cos_turns.h"
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
/// Inline: returned through memory from an out-of-line call, the sample's
/// copy stalled on store forwarding (a fifth of a distribution render's
/// shading loop).
LightSample sample_area_light(const AreaLight& light, const Vec3f& seen_from, Sample2 u);

/// The density by area with which sample_area_light(light, seen_from, .)
/// picks a point of the region it samples (for multiple importance sampling).
float area_light_pdf(const AreaLight& light, const Vec3f& seen_from);

/// The cap of a sphere of radius r seen from distance d: cos(alpha) >= r / d
/// about the axis toward the point; the whole sphere from inside.
inline float visible_cap_cos(float d, float r) { return d > r ? r / d : -1.0f; }

inline LightSample sample_area_light(const AreaLight& light, const Vec3f& seen_from, Sample2 u) {
    LightSample s;
    if (light.shape == AreaLightShape::Parallelogram) {
        s.point = light.corner + light.edge1 * u.x + light.edge2 * u.y;
        const Vec3f n = cross(light.edge1, light.edge2);
        const float area = length(n);
        s.normal = n / area;
        s.pdf_area = 1.0f / area;
        return s;
    }
    const Vec3f to_point = seen_from - light.center;
    const float d = length(to_point), r = light.radius;
    // Uniform by area on a cap: cos(alpha) uniform in [cos_min, 1].
    const float cos_min = visible_cap_cos(d, r);
    const float cos_a = 1.0f - u.x * (1.0f - cos_min);
    const float sin_a = std::sqrt(std::max(0.0f, 1.0f - cos_a * cos_a));
    float sin_phi, cos_phi;
    sin_cos_turns(u.y, sin_phi, cos_phi);
    const OrthonormalBasis<float> frame(d > 0 ? to_point / d : Vec3f{0, 0, 1});
    s.normal = frame.to_world({sin_a * cos_phi, sin_a * sin_phi, cos_a});
    s.point = light.center + s.normal * r;
    s.pdf_area = 1.0f / (2.0f * std::numbers::pi_v<float> * r * r * (1.0f - cos_min));
    return s;
}

}  // namespace raypack
