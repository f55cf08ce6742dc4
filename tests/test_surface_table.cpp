// SurfaceTable (render/surface.h) against surface_at: the same point,
// normals and material, bit for bit, at the hits of camera rays and of rays
// from every hit in random directions (hits all over each scene), on every
// shared SPD scene: spheres (balls), flat and smoothed triangles (gears,
// teapot's "pp" patches), cones (rings, tree).
#include <gtest/gtest.h>

#include <bit>
#include <random>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "render/camera_rays.h"
#include "render/surface.h"
#include "scene/load.h"
#include "tests/test_paths.h"

namespace raypack {
namespace {

void expect_same_bits(const Vec3f& a, const Vec3f& b, const char* what) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.x), std::bit_cast<std::uint32_t>(b.x)) << what;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.y), std::bit_cast<std::uint32_t>(b.y)) << what;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.z), std::bit_cast<std::uint32_t>(b.z)) << what;
}

class SurfaceTableTest : public ::testing::TestWithParam<const char*> {};

TEST_P(SurfaceTableTest, SameSurfacesAsSurfaceAt) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam() + ".nff");
    const auto accel = build_accel(scene, accel_config("bvh4"));
    const SurfaceTable table(scene);
    const CameraFrame frame = make_camera_frame(scene.camera, 64, 64);
    std::vector<Rayf> rays;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) rays.push_back(camera_ray(frame, float(x) + 0.5f, float(y) + 0.5f));
    std::vector<Hitf> hits(rays.size());
    accel->intersect(rays, hits);
    // Bounces: from each hit in a random direction.
    std::mt19937 rng(7);
    std::normal_distribution<float> normal;
    const std::size_t camera = rays.size();
    for (std::size_t i = 0; i < camera; ++i) {
        if (!hits[i].found()) continue;
        Rayf r;
        r.org = rays[i].org + rays[i].dir * (hits[i].t * 0.999f);
        r.dir = {normal(rng), normal(rng), normal(rng)};
        rays.push_back(r);
    }
    hits.resize(rays.size());
    accel->intersect(std::span(rays).subspan(camera), std::span(hits).subspan(camera));
    std::size_t compared = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!hits[i].found()) continue;
        const Surface want = surface_at(scene, rays[i], hits[i]);
        const Surface got = table.at(rays[i], hits[i]);
        expect_same_bits(got.point, want.point, "point");
        expect_same_bits(got.geometric_normal, want.geometric_normal, "geometric normal");
        expect_same_bits(got.shading_normal, want.shading_normal, "shading normal");
        EXPECT_EQ(got.material, want.material);
        ++compared;
    }
    EXPECT_GT(compared, 1000u);
}

INSTANTIATE_TEST_SUITE_P(SpdScenes, SurfaceTableTest,
                         ::testing::Values("balls", "gears", "mount", "rings", "teapot", "tetra", "tree"));

}  // namespace
}  // namespace raypack
