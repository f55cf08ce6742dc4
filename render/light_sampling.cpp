#include "render/light_sampling.h"

#include <numbers>

namespace raypack {

float area_light_pdf(const AreaLight& light, const Vec3f& seen_from) {
    if (light.shape == AreaLightShape::Parallelogram) return 1.0f / light.area();
    const float r = light.radius, cos_min = visible_cap_cos(length(seen_from - light.center), r);
    return 1.0f / (2.0f * std::numbers::pi_v<float> * r * r * (1.0f - cos_min));
}

}  // namespace raypack
