// SurfaceTable (render/surface.h) against surface_at, and SurfaceLanes
// (render/surface_lanes.h) against SurfaceTable::at: the same point,
// normals and material, bit for bit, at the hits of camera rays and of rays
// from every hit in random directions (hits all over each scene), on every
// shared SPD scene: spheres (balls), flat and smoothed triangles (gears,
// teapot's "pp" patches), cones (rings, tree).
#include <gtest/gtest.h>

#include <bit>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "render/camera_rays.h"
#include "render/shade_lanes.h"
#include "render/surface.h"
#include "render/surface_lanes.h"
#include "scene/load.h"
#include "tests/test_paths.h"

namespace raypack {
namespace {

void expect_same_bits(const Vec3f& a, const Vec3f& b, const char* what) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.x), std::bit_cast<std::uint32_t>(b.x)) << what;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.y), std::bit_cast<std::uint32_t>(b.y)) << what;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.z), std::bit_cast<std::uint32_t>(b.z)) << what;
}

/// Camera rays (64 x 64) and a random bounce from each of their hits, with
/// their closest hits.
void rays_with_hits(const Scene& scene, std::vector<Rayf>& rays, std::vector<Hitf>& hits) {
    const auto accel = build_accel(scene, accel_config("bvh4"));
    const CameraFrame frame = make_camera_frame(scene.camera, 64, 64);
    rays.clear();
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) rays.push_back(camera_ray(frame, float(x) + 0.5f, float(y) + 0.5f));
    hits.assign(rays.size(), Hitf{});
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
}

/// The scene GetParam() names, its table, and rays_with_hits.
class SurfaceTableTest : public ::testing::TestWithParam<const char*> {
protected:
    void SetUp() override {
        scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam() + ".nff");
        table = std::make_unique<SurfaceTable>(scene);
        rays_with_hits(scene, rays, hits);
    }
    Scene scene;
    std::unique_ptr<SurfaceTable> table;
    std::vector<Rayf> rays;
    std::vector<Hitf> hits;
};

TEST_P(SurfaceTableTest, SameSurfacesAsSurfaceAt) {
    std::size_t compared = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!hits[i].found()) continue;
        const Surface want = surface_at(scene, rays[i], hits[i]);
        const Surface got = table->at(rays[i], hits[i]);
        expect_same_bits(got.point, want.point, "point");
        expect_same_bits(got.geometric_normal, want.geometric_normal, "geometric normal");
        expect_same_bits(got.shading_normal, want.shading_normal, "shading normal");
        EXPECT_EQ(got.material, want.material);
        ++compared;
    }
    EXPECT_GT(compared, 1000u);
}

// Gathered lane by lane and loaded whole (consecutive rays, transposed in
// registers): the same bits.
TEST_P(SurfaceTableTest, LanesHoldTheTablesBits) {
    constexpr int K = kShadeLanes;
    using I = vint<K>;
    SurfaceLanes<K> lanes;
    for (const bool consecutive : {false, true}) {
        SCOPED_TRACE(consecutive ? "loaded" : "gathered");
        std::size_t compared = 0;
        for (std::size_t i0 = 0; i0 + K <= rays.size(); i0 += K) {
            alignas(64) std::int32_t index[K];
            std::uint32_t found = 0;
            for (int l = 0; l < K; ++l) {
                index[l] = std::int32_t(i0) + l;
                found |= std::uint32_t(hits[i0 + std::size_t(l)].found()) << l;
            }
            if (found == 0) continue;
            if (consecutive) lanes.load(*table, rays.data(), hits.data(), i0, I::load_aligned(index), found);
            else lanes.gather(*table, rays.data(), hits.data(), I::load_aligned(index), found);
            alignas(64) float lane[9][K];
            alignas(64) std::int32_t material[K];
            for (int a = 0; a < 3; ++a) {
                lanes.point[a].store_aligned(lane[a]);
                lanes.geometric_normal[a].store_aligned(lane[3 + a]);
                lanes.shading_normal[a].store_aligned(lane[6 + a]);
            }
            lanes.material.store_aligned(material);
            for (int l = 0; l < K; ++l) {
                if (!((found >> l) & 1u)) continue;
                const Surface want = table->at(rays[i0 + std::size_t(l)], hits[i0 + std::size_t(l)]);
                expect_same_bits({lane[0][l], lane[1][l], lane[2][l]}, want.point, "point");
                expect_same_bits({lane[3][l], lane[4][l], lane[5][l]}, want.geometric_normal, "geometric normal");
                expect_same_bits({lane[6][l], lane[7][l], lane[8][l]}, want.shading_normal, "shading normal");
                EXPECT_EQ(std::uint32_t(material[l]), want.material);
                ++compared;
            }
        }
        EXPECT_GT(compared, 1000u);
    }
}

INSTANTIATE_TEST_SUITE_P(SpdScenes, SurfaceTableTest,
                         ::testing::Values("balls", "gears", "mount", "rings", "teapot", "tetra", "tree"));

}  // namespace
}  // namespace raypack
