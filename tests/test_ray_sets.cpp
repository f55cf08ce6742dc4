// The standard ray sets: diffuse bounce rays are deterministic, leave the
// surface into the hemisphere the camera ray came from, and follow the
// cosine law (mean cos(theta) = 2/3 for density cos(theta) / pi).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>

#include "accel/accel.h"
#include "measure/ray_sets.h"
#include "render/surface.h"
#include "scene/load.h"

namespace raypack {
namespace {

bool same_bits(const std::vector<Rayf>& a, const std::vector<Rayf>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Rayf)) == 0;
}

TEST(DiffuseRaySet, SameEveryRunAndForAnyThreadCount) {
    const Scene scene = load_scene("gen:balls:2");
    const std::vector<Rayf> a = diffuse_ray_set(scene, 64, 64, 42);
    std::vector<Rayf> b;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        b = diffuse_ray_set(scene, 64, 64, 42);
    }
    ASSERT_FALSE(a.empty());
    EXPECT_TRUE(same_bits(a, b));
    EXPECT_FALSE(same_bits(a, diffuse_ray_set(scene, 64, 64, 43))) << "the seed must change the directions";
}

/// Each ray against the surface it leaves: the normal facing the camera.
struct Bounce {
    Rayf ray;
    Vec3f normal;
};

std::vector<Bounce> bounces(const Scene& scene, int w, int h) {
    const std::vector<Rayf> camera = camera_ray_set(scene, w, h);
    const std::vector<Rayf> diffuse = diffuse_ray_set(scene, w, h, 7);
    const auto accel = build_accel(scene, AccelConfig{});
    std::vector<Bounce> out;
    std::size_t next = 0;
    for (const Rayf& c : camera) {
        const Hitf hit = accel->intersect1(c);
        if (!hit.found()) continue;
        const Surface s = surface_at(scene, c, hit);
        out.push_back({diffuse.at(next++), dot(s.shading_normal, c.dir) < 0 ? s.shading_normal : -s.shading_normal});
    }
    EXPECT_EQ(next, diffuse.size()) << "one diffuse ray per camera hit";
    return out;
}

TEST(DiffuseRaySet, UnitDirectionsInTheHemisphereFacingTheCamera) {
    const Scene scene = load_scene("gen:tetra:3");
    for (const Bounce& b : bounces(scene, 48, 48)) {
        EXPECT_NEAR(length(b.ray.dir), 1.0f, 1e-5f);
        EXPECT_GE(dot(b.ray.dir, b.normal), -1e-6f);
        EXPECT_EQ(b.ray.tnear, 0.0f);
        EXPECT_TRUE(std::isinf(b.ray.tfar));
    }
}

TEST(DiffuseRaySet, CosineWeighted) {
    // balls: curved surfaces, so many different normals. Mean cos = 2/3 and
    // mean cos^2 = 1/2 under p = cos/pi; the standard error with n ~ 1e5 rays
    // is ~ 1e-3, so 5e-3 fails a uniform hemisphere (mean cos 1/2) by far.
    const Scene scene = load_scene("gen:balls:2");
    double sum = 0, sum2 = 0;
    const std::vector<Bounce> all = bounces(scene, 400, 400);
    ASSERT_GT(all.size(), 50000u);
    for (const Bounce& b : all) {
        const double c = dot(b.ray.dir, b.normal);
        sum += c;
        sum2 += c * c;
    }
    EXPECT_NEAR(sum / double(all.size()), 2.0 / 3.0, 5e-3);
    EXPECT_NEAR(sum2 / double(all.size()), 0.5, 5e-3);
}

}  // namespace
}  // namespace raypack
