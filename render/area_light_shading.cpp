// The light of one area light at all shaded points of a level, in SIMD
// lanes over the points (render/shading_points.h), bit for bit the scalar
// expressions the Whitted wavefront used per point.
#include <bit>
#include <cmath>
#include <vector>

#include "render/light_lanes.h"
#include "render/light_sampling.h"
#include "render/ray_offset.h"
#include "render/sin_cos_turns.h"

namespace raypack {

struct AreaLightLanes : LightLanes {
    /// What one light sample gives a block of K points: the lanes it lights
    /// and, per lane, its point on the light and its contribution.
    struct SampleLanes {
        std::uint32_t lit;
        alignas(64) float point[3][K];
        alignas(64) float contribution[3][K];
    };

    static std::size_t run(const ShadingPoints& pts, const AreaLight& light, std::span<const Sample2> drawn,
                           int samples, float intensity, bool facing_point, const RayOffset& offset,
                           ShadowQueue& out) {
        // A parallelogram's normal and the light's share of the intensity,
        // as sample_area_light and the scalar shading computed them.
        const LightSample constant = sample_area_light(light, {}, {});
        const Vec3f share = light.color * (intensity / float(samples));
        const bool parallelogram = light.shape == AreaLightShape::Parallelogram;
        thread_local std::vector<SampleLanes> lanes;
        lanes.resize(std::size_t(samples));
        std::size_t emitted = 0;
        alignas(64) float ux[K], uy[K];
        for (std::size_t j = 0; j < pts.count_; j += K) {
            const std::size_t left = pts.count_ - j;
            const int count = left >= std::size_t(K) ? K : int(left);
            const std::uint32_t in_range = (1u << count) - 1;  // count <= K <= 16
            const Vec3<F> above = load3(pts.above_, j);
            const Vec3<F> ns = load3(pts.ns_, j), ng = load3(pts.ng_, j), view = load3(pts.view_, j);
            std::uint32_t any_lit = 0;
            for (int k = 0; k < samples; ++k) {
                SampleLanes& out_k = lanes[std::size_t(k)];
                for (int l = 0; l < K; ++l) {
                    // Lanes past the last point repeat it (masked off below).
                    const std::size_t p = j + std::size_t(l < count ? l : count - 1);
                    const Sample2 u = drawn[p * std::size_t(samples) + std::size_t(k)];
                    ux[l] = u.x;
                    uy[l] = u.y;
                }
                Vec3<F> point, normal;
                if (parallelogram) {
                    const F x = load_lanes<F>(ux), y = load_lanes<F>(uy);
                    point = Vec3<F>{F(light.corner.x), F(light.corner.y), F(light.corner.z)} +
                            Vec3<F>{F(light.edge1.x), F(light.edge1.y), F(light.edge1.z)} * x +
                            Vec3<F>{F(light.edge2.x), F(light.edge2.y), F(light.edge2.z)} * y;
                    normal = {F(constant.normal.x), F(constant.normal.y), F(constant.normal.z)};
                } else {
                    // sample_area_light on the cap each point sees.
                    const Vec3<F> center{F(light.center.x), F(light.center.y), F(light.center.z)};
                    const F radius(light.radius);
                    const Vec3<F> to_point = above - center;
                    const F d = vsqrt(dot(to_point, to_point));
                    const F cos_min = select(d > radius, radius / d, F(-1.0f));  // visible_cap_cos
                    const F x = facing_point ? F(0.0f) : load_lanes<F>(ux);
                    const F y = facing_point ? F(0.0f) : load_lanes<F>(uy);
                    const F cos_a = F(1.0f) - x * (F(1.0f) - cos_min);
                    const F sin_a = vsqrt(std_max(F(0.0f), F(1.0f) - cos_a * cos_a));
                    F sin_phi, cos_phi;
                    sin_cos_turns(y, sin_phi, cos_phi);
                    const auto away = d > F(0.0f);  // not at the centre
                    const Vec3<F> axis{select(away, to_point.x / d, F(0.0f)),
                                       select(away, to_point.y / d, F(0.0f)),
                                       select(away, to_point.z / d, F(1.0f))};
                    normal = to_world_lanes(axis, sin_a * cos_phi, sin_a * sin_phi, cos_a);
                    point = center + normal * radius;
                }
                const Vec3<F> to_light = point - above;
                const F dist = vsqrt(dot(to_light, to_light));
                // `!(dist > 0) || dot(normal, to_light) >= 0`: behind the emitting side.
                std::uint32_t lit = in_range & mask_bits(dist > F(0.0f)) & ~mask_bits(dot(normal, to_light) >= F(0.0f));
                const Vec3<F> l = to_light / dist;
                const F ns_l = dot(ns, l);
                lit &= ~mask_bits(ns_l <= F(0.0f)) & ~mask_bits(dot(ng, l) <= F(0.0f));
                out_k.lit = lit;
                if (lit == 0) continue;
                any_lit |= lit;
                const Vec3<F> lc{F(share.x), F(share.y), F(share.z)};
                direct(pts, j, lit, ns, l, ns_l, view, lc, out_k.contribution);
                for (int a = 0; a < 3; ++a) store_lanes(out_k.point[a], point[a]);
            }
            if (any_lit == 0) continue;
            if (samples == 1) {
                // One sample a point: the points' order is the lanes'.
                const SampleLanes& in = lanes[0];
                const Vec3<F> target{load_lanes<F>(in.point[0]), load_lanes<F>(in.point[1]), load_lanes<F>(in.point[2])};
                const std::size_t n = std::size_t(std::popcount(in.lit));
                emit(pts, j, in.lit, above, target, in.contribution, offset.tnear(), out.append(n));
                emitted += n;
                continue;
            }
            std::size_t n = 0;
            for (int k = 0; k < samples; ++k) n += std::size_t(std::popcount(lanes[std::size_t(k)].lit));
            const ShadowQueue::Run run = out.append(n);
            // Point by point, sample by sample: the scalar loops' order.
            std::size_t e = 0;
            for (std::uint32_t bits = any_lit; bits != 0; bits &= bits - 1) {
                const int i = std::countr_zero(bits);
                const std::size_t p = j + std::size_t(i);
                for (int k = 0; k < samples; ++k) {
                    const SampleLanes& in = lanes[std::size_t(k)];
                    if (!((in.lit >> i) & 1u)) continue;
                    Rayf& ray = run.rays[e];  // spawn_ray_to, component by component
                    ray.org.x = pts.above_[0][p];
                    ray.org.y = pts.above_[1][p];
                    ray.org.z = pts.above_[2][p];
                    ray.dir.x = in.point[0][i] - ray.org.x;
                    ray.dir.y = in.point[1][i] - ray.org.y;
                    ray.dir.z = in.point[2][i] - ray.org.z;
                    ray.tnear = offset.tnear();
                    ray.tfar = kShadowRayEnd;
                    run.owner[e] = pts.ray_[p];
                    run.contribution[e] = {in.contribution[0][i], in.contribution[1][i], in.contribution[2][i]};
                    ++e;
                }
            }
            emitted += e;
        }
        return emitted;
    }
};

std::size_t shade_area_light(const ShadingPoints& points, const AreaLight& light, std::span<const Sample2> drawn,
                             int samples, float intensity, bool facing_point, const RayOffset& offset,
                             ShadowQueue& out) {
    return AreaLightLanes::run(points, light, drawn, samples, intensity, facing_point, offset, out);
}

}  // namespace raypack
