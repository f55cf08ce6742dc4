// Feature-set specialisation (accel/prims/prim_kinds.h, issue 18 step 4):
// which loops a build chooses, and that the loops compiled for triangles
// alone answer bit for bit as the general ones.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "accel/accel.h"
#include "oracle_harness.h"
#include "scene/load.h"

namespace raypack {
namespace {

using namespace oracle_harness;

TEST(Specialisation, ChosenFromWhatTheSceneHolds) {
    const Scene tetra = load_scene("gen:tetra:3"), balls = load_scene("gen:balls:1");
    const Scene placed = load_scene("gen:tetra-instanced:3"), terrain = load_scene("gen:terrain:2");
    KernelChoice k;
    EXPECT_EQ(specialisation_for(tetra, k), KindSpecialisation::Triangles);
    EXPECT_EQ(specialisation_for(balls, k), KindSpecialisation::General);
    EXPECT_EQ(specialisation_for(placed, k), KindSpecialisation::General);
    EXPECT_EQ(specialisation_for(terrain, k), KindSpecialisation::General);
    EXPECT_EQ(specialisation_for(*placed.objects[0], k), KindSpecialisation::Triangles);  // the object itself
    k.specialise = false;
    EXPECT_EQ(specialisation_for(tetra, k), KindSpecialisation::General);
    k = {};
    k.triangle = TriangleMethod::Watertight;  // compiled for the default kernels only
    EXPECT_EQ(specialisation_for(tetra, k), KindSpecialisation::General);
    k = {};
    k.precision = Precision::Double;
    EXPECT_EQ(specialisation_for(tetra, k), KindSpecialisation::General);
    for (const char* kind : {"bvh4", "bvh8"}) {
        EXPECT_EQ(build_accel(tetra, accel_config(kind))->stats().specialisation, KindSpecialisation::Triangles);
        EXPECT_EQ(build_accel(balls, accel_config(kind))->stats().specialisation, KindSpecialisation::General);
    }
}

TEST(Specialisation, TriangleLoopsAnswerAsTheGeneralOnesBitForBit) {
    const Scene scene = load_scene("gen:teapot:4");
    std::mt19937 rng(5);
    std::vector<Rayf> rays = camera_rays(scene, 48);
    for (const Rayf& r : random_rays(scene, rng, 3000, 0.2f)) rays.push_back(r);
    KernelChoice general;
    general.specialise = false;
    for (const char* kind : {"bvh4", "bvh8"}) {
        const auto fast = build_accel(scene, accel_config(kind));
        const auto slow = build_accel(scene, accel_config(kind, general));
        ASSERT_EQ(fast->stats().specialisation, KindSpecialisation::Triangles);
        ASSERT_EQ(slow->stats().specialisation, KindSpecialisation::General);
        for (int width : {1, 4, 8, 16}) {
            if (!fast->supports_packet(width)) continue;
            const std::vector<Hitf> a = trace_hits(*fast, rays, width), b = trace_hits(*slow, rays, width);
            EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Hitf)), 0) << kind << " width " << width;
            EXPECT_EQ(trace_occlusion(*fast, rays, width), trace_occlusion(*slow, rays, width))
                << kind << " width " << width;
        }
    }
}

}  // namespace
}  // namespace raypack
