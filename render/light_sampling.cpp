#include "render/light_sampling.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/sampling.h"

namespace raypack {
namespace {

/// The cap of a sphere of radius r seen from distance d: cos(alpha) >= r / d
/// about the axis toward the point; the whole sphere from inside.
float visible_cap_cos(float d, float r) { return d > r ? r / d : -1.0f; }

}  // namespace

LightSample sample_area_light(const AreaLight& light, const Vec3f& seen_from, Sample2 u) {
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
    const float phi = 2.0f * std::numbers::pi_v<float> * u.y;
    const OrthonormalBasis<float> frame(d > 0 ? to_point / d : Vec3f{0, 0, 1});
    s.normal = frame.to_world({sin_a * std::cos(phi), sin_a * std::sin(phi), cos_a});
    s.point = light.center + s.normal * r;
    s.pdf_area = 1.0f / (2.0f * std::numbers::pi_v<float> * r * r * (1.0f - cos_min));
    return s;
}

float area_light_pdf(const AreaLight& light, const Vec3f& seen_from) {
    if (light.shape == AreaLightShape::Parallelogram) return 1.0f / light.area();
    const float r = light.radius, cos_min = visible_cap_cos(length(seen_from - light.center), r);
    return 1.0f / (2.0f * std::numbers::pi_v<float> * r * r * (1.0f - cos_min));
}

}  // namespace raypack
