// The standard ray sets: diffuse bounce rays are deterministic, leave the
// surface into the hemisphere the camera ray came from, and follow the
// cosine law (mean cos(theta) = 2/3 for density cos(theta) / pi); sets in
// tiles are the rows' rays, each once, in patches of 4 x 2 and 4 x 4.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

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

bool same_ray(const Rayf& a, const Rayf& b) { return std::memcmp(&a, &b, sizeof(Rayf)) == 0; }

TEST(CameraRaySet, TilesAreTheRowsRaysInPatches) {
    const Scene scene = load_scene("gen:balls:1");
    for (auto [w, h] : {std::pair{64, 48}, std::pair{37, 21}}) {
        const std::vector<Rayf> rows = camera_ray_set(scene, w, h);
        const std::vector<Rayf> tiles = camera_ray_set(scene, w, h, nullptr, PixelOrder::Tiles);
        ASSERT_EQ(rows.size(), tiles.size());
        // Each tiled ray is some pixel's, and no pixel comes twice.
        std::vector<int> seen(rows.size(), 0);
        std::vector<int> pixel_of(tiles.size(), -1);
        for (std::size_t i = 0; i < tiles.size(); ++i) {
            for (std::size_t p = 0; p < rows.size(); ++p)
                if (!seen[p] && same_ray(rows[p], tiles[i])) {
                    seen[p] = 1;
                    pixel_of[i] = int(p);
                    break;
                }
            ASSERT_GE(pixel_of[i], 0) << "tiled ray " << i << " is no pixel's ray (or a repeat)";
        }
        // Away from the ragged edges, every 8 (16) consecutive rays are a 4 x 2 (4 x 4) patch.
        for (std::size_t first = 0; first + 16 <= tiles.size(); first += 16) {
            int x0 = w, y0 = h, x1 = -1, y1 = -1;
            for (std::size_t i = first; i < first + 16; ++i) {
                const int x = pixel_of[i] % w, y = pixel_of[i] / w;
                x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
            }
            if (w % 8 == 0 && h % 8 == 0) {
                EXPECT_EQ(x1 - x0, 3) << "rays " << first << "..: not 4 pixels wide";
                EXPECT_EQ(y1 - y0, 3) << "rays " << first << "..: not 4 pixels tall";
                const int x = pixel_of[first] % w, y = pixel_of[first] / w;
                EXPECT_EQ(pixel_of[first + 7], (y + 1) * w + x + 3) << "the first 8 of a block are its top two rows";
            }
        }
    }
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
