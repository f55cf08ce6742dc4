// The light of one point light at all shaded points of a level, in SIMD
// lanes (render/shading_points.h).
#include <bit>
#include <cmath>

#include "render/light_lanes.h"
#include "render/ray_offset.h"

namespace raypack {

struct PointLightLanes : LightLanes {
    static std::size_t run(const ShadingPoints& pts, const PointLight& light, float intensity,
                           const Attenuation& att, const RayOffset& offset, ShadowQueue& out) {
        const Vec3<F> position{F(light.position.x), F(light.position.y), F(light.position.z)};
        std::size_t emitted = 0;
        alignas(64) float contribution[3][K];
        for (std::size_t j = 0; j < pts.count_; j += K) {
            const std::size_t left = pts.count_ - j;
            const std::uint32_t in_range = left >= std::size_t(K) ? (1u << K) - 1 : (1u << left) - 1;
            const Vec3<F> above = load3(pts.above_, j);
            const Vec3<F> ns = load3(pts.ns_, j), ng = load3(pts.ng_, j), view = load3(pts.view_, j);
            // The recursive tracer's expressions, lane by lane (whitted.cpp).
            const Vec3<F> to_light = position - above;
            const F dist = vsqrt(dot(to_light, to_light));
            const Vec3<F> l = to_light / dist;
            const F ns_l = dot(ns, l), ng_l = dot(ng, l);
            // `ns_l <= 0 || ng_l <= 0` skips the light: NaN lanes go on, as there.
            std::uint32_t faces = in_range & ~mask_bits(ns_l <= F(0.0f)) & ~mask_bits(ng_l <= F(0.0f));
            if (faces == 0) continue;
            const F atten = F(1.0f) / (F(att.c2) * dist * dist + F(att.c1) * dist + F(att.c0));
            const F scale = F(intensity) * atten;
            const Vec3<F> light_color{F(light.color.x) * scale, F(light.color.y) * scale, F(light.color.z) * scale};
            direct(pts, j, faces, ns, l, ns_l, view, light_color, contribution);
            const std::size_t n = std::size_t(std::popcount(faces));
            emit(pts, j, faces, above, position, contribution, offset.tnear(), out.append(n));
            emitted += n;
        }
        return emitted;
    }
};

std::size_t shade_point_light(const ShadingPoints& points, const PointLight& light, float intensity,
                              const Attenuation& attenuation, const RayOffset& offset, ShadowQueue& out) {
    return PointLightLanes::run(points, light, intensity, attenuation, offset, out);
}

}  // namespace raypack
