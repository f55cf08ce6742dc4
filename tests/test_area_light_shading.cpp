// shade_area_light (render/area_light_shading.cpp) lights a level's points
// in SIMD lanes; against the scalar expressions it replaced, point by point
// and sample by sample: the same shadow rays, owners and contributions, bit
// for bit, for parallelogram and sphere lights, ragged blocks, points behind
// the light or facing away, and Phong highlights.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>
#include <vector>

#include "render/light_sampling.h"
#include "render/phong_power.h"
#include "render/ray_offset.h"
#include "render/shading_points.h"

namespace raypack {
namespace {

struct Point {
    Vec3f view, ns, ng, above;
    Material m;
    float cutoff;
};

Vec3f unit(std::mt19937& rng) {
    std::normal_distribution<float> g;
    const Vec3f v{g(rng), g(rng), g(rng)};
    return normalize(v);
}

/// The Whitted wavefront's scalar area-light shading of one point (before
/// the lanes): sample, facing tests, Lambert plus Phong.
void scalar_shading(const Point& p, std::int32_t owner, const AreaLight& light, std::span<const Sample2> drawn,
                    int samples, float intensity, bool facing_point, const RayOffset& offset, ShadowQueue& out) {
    const Vec3f share = light.color * (intensity / float(samples));
    for (int k = 0; k < samples; ++k) {
        Sample2 u = drawn[std::size_t(k)];
        if (facing_point) u = {0, 0};
        const LightSample ls = sample_area_light(light, p.above, u);
        const Vec3f to_light = ls.point - p.above;
        const float dist = length(to_light);
        if (!(dist > 0) || dot(ls.normal, to_light) >= 0) continue;
        const Vec3f l = to_light / dist;
        if (dot(p.ns, l) <= 0 || dot(p.ng, l) <= 0) continue;
        spawn_ray_to(p.above, ls.point, offset, *out.rays.append(1));
        out.owner.push_back(owner);
        const float diffuse = p.m.kd * dot(p.ns, l);
        const Vec3f r = p.ns * (2.0f * dot(p.ns, l)) - l;
        const float rv = std::max(0.0f, -dot(r, p.view));
        const float specular = p.m.ks > 0 && rv > p.cutoff ? p.m.ks * phong_power(rv, p.m.shine) : 0.0f;
        out.contribution.push_back(share * p.m.color * diffuse + share * specular);
    }
}

bool same_bits(const Vec3f& a, const Vec3f& b) {
    return std::bit_cast<std::uint32_t>(a.x) == std::bit_cast<std::uint32_t>(b.x) &&
           std::bit_cast<std::uint32_t>(a.y) == std::bit_cast<std::uint32_t>(b.y) &&
           std::bit_cast<std::uint32_t>(a.z) == std::bit_cast<std::uint32_t>(b.z);
}

TEST(AreaLightShading, LanesAreTheScalarShadingBitForBit) {
    AreaLight quad;
    quad.shape = AreaLightShape::Parallelogram;
    quad.corner = {-1, -1, 3};
    quad.edge1 = {0, 2, 0};
    quad.edge2 = {2, 0, 0.3f};  // e1 x e2 points down, toward most points
    quad.color = {1, 0.8f, 0.6f};
    AreaLight sphere;
    sphere.shape = AreaLightShape::Sphere;
    sphere.center = {0.5f, -0.5f, 2.5f};
    sphere.radius = 0.4f;
    sphere.color = {0.7f, 0.7f, 1};
    const RayOffset offset(OffsetPolicy::Scaled, 10.0f);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f), coord(-2.0f, 2.0f);
    std::size_t lit[2] = {0, 0}, highlights = 0;
    for (const std::size_t count : {std::size_t(1), std::size_t(7), std::size_t(16), std::size_t(37)}) {
        std::vector<Point> points(count);
        ShadingPoints pts;
        for (std::size_t j = 0; j < count; ++j) {
            Point& p = points[j];
            // A fifth above the quad, which they see from behind.
            p.above = {coord(rng), coord(rng), j % 5 == 4 ? 3.5f : coord(rng) * 0.5f + 0.5f};
            p.ns = unit(rng);
            if (j % 3 != 0) p.ns.z = std::fabs(p.ns.z);  // most face the lights, some not
            p.ng = normalize(p.ns + unit(rng) * 0.2f);
            p.view = unit(rng);
            p.m.color = {u01(rng), u01(rng), u01(rng)};
            p.m.kd = u01(rng);
            p.m.ks = j % 2 ? u01(rng) : 0.0f;
            p.m.shine = 1 + 50 * u01(rng);
            p.cutoff = j % 4 == 1 ? 0.999f : 0.0f;
            pts.add(std::int32_t(100 + j), p.view, p.ns, p.ng, p.above, p.m, p.cutoff);
        }
        for (const AreaLight* light : {&quad, &sphere}) {
            for (const int samples : {1, 3, 4}) {
                for (const bool facing_point : {false, true}) {
                    if (facing_point && light->shape != AreaLightShape::Sphere) continue;
                    std::vector<Sample2> drawn(count * std::size_t(samples));
                    for (Sample2& d : drawn) d = {u01(rng), u01(rng)};
                    ShadowQueue lanes, scalar;
                    const std::size_t n =
                        shade_area_light(pts, *light, drawn, samples, 0.3f, facing_point, offset, lanes);
                    for (std::size_t j = 0; j < count; ++j)
                        scalar_shading(points[j], std::int32_t(100 + j), *light,
                                       std::span(drawn).subspan(j * std::size_t(samples), std::size_t(samples)),
                                       samples, 0.3f, facing_point, offset, scalar);
                    ASSERT_EQ(n, lanes.rays.size());
                    ASSERT_EQ(lanes.rays.size(), scalar.rays.size()) << count << " points, " << samples << " samples";
                    lit[light == &sphere] += n;
                    for (std::size_t i = 0; i < n; ++i) {
                        EXPECT_EQ(lanes.owner[i], scalar.owner[i]);
                        EXPECT_TRUE(same_bits(lanes.rays[i].org, scalar.rays[i].org)) << i;
                        EXPECT_TRUE(same_bits(lanes.rays[i].dir, scalar.rays[i].dir)) << i;
                        EXPECT_EQ(lanes.rays[i].tfar, scalar.rays[i].tfar);
                        EXPECT_EQ(lanes.rays[i].tnear, scalar.rays[i].tnear);
                        EXPECT_TRUE(same_bits(lanes.contribution[i], scalar.contribution[i])) << i;
                        highlights += scalar.contribution[i].x > 0 && lanes.contribution[i].x != 0;
                    }
                }
            }
        }
    }
    EXPECT_GT(lit[0], 100u);  // both lights lit points: not only rejections were compared
    EXPECT_GT(lit[1], 100u);
    EXPECT_GT(highlights, 50u);
}

}  // namespace
}  // namespace raypack
