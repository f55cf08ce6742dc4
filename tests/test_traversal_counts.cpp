// Accel::count_traversal: the counting walk must be the single-ray walk with
// counters, so its answers equal intersect()/occluded() ray for ray, and its
// counts must behave (brute force tests every primitive, a tree far fewer).
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "tests/oracle_harness.h"
#include "accel/accel.h"
#include "render/camera_rays.h"
#include "measure/ray_sets.h"
#include "scene/load.h"

namespace raypack {

using namespace raypack::oracle_harness;
namespace {

class TraversalCountsTest : public ::testing::TestWithParam<std::string> {};

/// Camera rays plus random rays from inside the scene's box.
std::vector<Rayf> test_rays(const Scene& scene) {
    std::vector<Rayf> rays = camera_ray_set(scene, 48, 48);
    std::mt19937 rng(7);
    const Box3f box = scene_bounds(scene);
    for (int i = 0; i < 1000; ++i) rays.push_back(Rayf{random_point(rng, box), random_direction(rng)});
    return rays;
}

void expect_same_answers(const std::string& kind, const std::string& scene_spec) {
    const Scene scene = load_scene(scene_spec);
    const auto accel = build_accel(scene, accel_config(kind));
    const std::vector<Rayf> rays = test_rays(scene);
    std::vector<Hitf> expected(rays.size()), counted(rays.size());
    accel->intersect(rays, expected);
    TraversalCounts closest;
    ASSERT_TRUE(accel->count_traversal(rays, false, counted, closest));
    for (std::size_t i = 0; i < rays.size(); ++i) {
        ASSERT_EQ(expected[i].prim, counted[i].prim) << kind << " ray " << i << ": " << describe(rays[i]);
        if (expected[i].found()) {
            ASSERT_EQ(expected[i].t, counted[i].t) << kind << " ray " << i;
        }
    }
    std::vector<std::uint8_t> occluded(rays.size());
    accel->occluded(rays, occluded);
    TraversalCounts any;
    ASSERT_TRUE(accel->count_traversal(rays, true, counted, any));
    for (std::size_t i = 0; i < rays.size(); ++i)
        ASSERT_EQ(occluded[i] != 0, counted[i].found()) << kind << " ray " << i << ": " << describe(rays[i]);
    // (Any hit may do more work than closest hit: the wide BVHs take children
    // unordered for occlusion, without the closest hit's distance culling.)
    EXPECT_GT(any.prims, 0u) << kind;
    EXPECT_GT(closest.prims, 0u) << kind;
    if (kind != "brute") {
        EXPECT_GT(closest.nodes, 0u) << kind;
        EXPECT_LT(closest.prims, rays.size() * scene.primitive_count() / 4) << kind << " tests too many primitives";
        // Havran's measures nest: N_EETS <= N_ETS <= N_TS; a BVH has no
        // empty leaves, a grid's steps are all cells, and the rays from
        // inside the box all enter some leaf.
        for (const TraversalCounts& c : {closest, any}) {
            EXPECT_GT(c.leaves, 0u) << kind;
            EXPECT_LE(c.leaves, c.nodes) << kind;
            EXPECT_LE(c.empty_leaves, c.leaves) << kind;
            if (kind.rfind("bvh", 0) == 0) {
                EXPECT_EQ(c.empty_leaves, 0u) << kind;
            }
            if (kind == "grid") {
                EXPECT_EQ(c.leaves, c.nodes);
            }
        }
    } else {
        EXPECT_EQ(closest.prims, rays.size() * scene.primitive_count());
    }
}

TEST_P(TraversalCountsTest, CountingWalkGivesTheSameAnswersOnBalls) { expect_same_answers(GetParam(), "gen:balls:3"); }
TEST_P(TraversalCountsTest, CountingWalkGivesTheSameAnswersOnTetra) { expect_same_answers(GetParam(), "gen:tetra:4"); }
TEST_P(TraversalCountsTest, CountingWalkGivesTheSameAnswersOnMount) { expect_same_answers(GetParam(), "gen:mount:3"); }

std::vector<std::string> countable_kinds() {
    std::vector<std::string> kinds;
    for (const char* k : accel_kinds())
        if (!is_embree_kind(k)) kinds.push_back(k);
    return kinds;
}

INSTANTIATE_TEST_SUITE_P(Accels, TraversalCountsTest, ::testing::ValuesIn(countable_kinds()), param_name);

#ifdef RAYPACK_HAVE_EMBREE
TEST(TraversalCounts, EmbreeSaysItCannotCount) {
    const Scene scene = load_scene("gen:balls:1");
    const auto accel = build_accel(scene, accel_config("embree"));
    std::vector<Rayf> rays = camera_ray_set(scene, 4, 4);
    std::vector<Hitf> hits(rays.size());
    TraversalCounts counts;
    EXPECT_FALSE(accel->count_traversal(rays, false, hits, counts));
}
#endif

}  // namespace
}  // namespace raypack
