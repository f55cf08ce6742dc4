// The traversal-cost heat map: geometry costs more than background, the
// legend is drawn below the picture, and the CLI writes it for every
// structure that can count.
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <cstdlib>
#include <filesystem>

#include "accel/accel.h"
#include "measure/colormap.h"
#include "measure/cost_map.h"
#include "scene/load.h"

namespace raypack {
namespace {

bool near(const Vec3f& a, const Vec3f& b) {
    return std::abs(a.x - b.x) < 0.02f && std::abs(a.y - b.y) < 0.02f && std::abs(a.z - b.z) < 0.02f;
}

TEST(CostMap, GeometryCostsMoreThanBackground) {
    const Scene scene = load_scene("gen:tetra:3");
    for (const char* kind : {"bvh2", "bvh8", "grid", "kdtree", "octree"}) {
        const auto accel = build_accel(scene, accel_config(kind));
        const CostMap map = primary_ray_cost(scene, *accel, 96, 96);
        double on = 0, off = 0;
        std::size_t n_on = 0, n_off = 0;
        for (std::size_t i = 0; i < map.cost.size(); ++i) {
            (map.hit[i] ? on : off) += map.cost[i];
            ++(map.hit[i] ? n_on : n_off);
        }
        ASSERT_GT(n_on, 100u) << kind;
        ASSERT_GT(n_off, 100u) << kind;
        EXPECT_GT(on / double(n_on), 1.5 * off / double(n_off)) << kind;
        EXPECT_LT(map.min, map.max) << kind;
    }
}

TEST(CostMap, HeatMapHasAScaleBelowThePicture) {
    CostMap map;
    map.width = 300;
    map.height = 10;
    for (int i = 0; i < 3000; ++i) map.cost.push_back(std::uint32_t(i % 300) + 5);
    map.hit.assign(map.cost.size(), 1);
    map.min = 5;
    map.max = 304;
    const Image image = cost_heat_map(map);
    ASSERT_EQ(image.width, 300);
    ASSERT_EQ(image.height, 10 + cost_legend_height(300));
    EXPECT_TRUE(near(image.at(0, 0), viridis(0.0f)));
    EXPECT_TRUE(near(image.at(299, 0), viridis(1.0f)));
    const int bar = 10 + 6;
    EXPECT_TRUE(near(image.at(4, bar), viridis(0.0f)));
    EXPECT_TRUE(near(image.at(295, bar), viridis(1.0f)));
    int white = 0;
    for (int y = bar + 6; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) white += near(image.at(x, y), {1, 1, 1});
    EXPECT_GT(white, 40) << "min and max labels";
}

TEST(CostMap, CliWritesTheHeatMap) {
    const auto out = std::filesystem::temp_directory_path() / "raypack_cost_map.png";
    std::filesystem::remove(out);
    const std::string cmd =
        std::string(RAYPACK_CLI) + " render gen:balls:2 --accel kdtree --aov cost --res 64 48 -o " + out.string() + " >/dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const Image image = read_image(out.string());
    EXPECT_EQ(image.width, 64);
    EXPECT_EQ(image.height, 48 + cost_legend_height(64));
    const std::string bad = std::string(RAYPACK_CLI) + " render gen:balls:2 --aov depth -o " + out.string() + " 2>/dev/null";
    EXPECT_NE(std::system(bad.c_str()), 0);
}

}  // namespace
}  // namespace raypack
