// The wavefront renderer against the recursive tracer it replaced
// (tests/reference_whitted.h): the same pixels bit for bit and the same ray
// counts, on every shared SPD scene, at several depths, packet widths and
// offset policies.
#include <gtest/gtest.h>

#include <string>

#include "accel/accel.h"
#include "render/tiles.h"
#include "render/whitted.h"
#include "scene/load.h"
#include "tests/reference_whitted.h"
#include "tests/test_paths.h"

namespace raypack {
namespace {

void expect_same_render(const Scene& scene, const Accel& accel, const WhittedOptions& options) {
    RenderStats want;
    const Image reference = reference::render_whitted_recursive(scene, accel, options, want);
    Image image;
    const RenderStats got = render_whitted(scene, accel, options, image);
    ASSERT_EQ(image.width, reference.width);
    ASSERT_EQ(image.height, reference.height);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < image.rgb.size(); ++i) differ += image.rgb[i] != reference.rgb[i];
    EXPECT_EQ(differ, 0u) << "of " << image.rgb.size() << " channel values";
    EXPECT_EQ(got.eye_rays, want.eye_rays);
    EXPECT_EQ(got.eye_hits, want.eye_hits);
    EXPECT_EQ(got.reflect_rays, want.reflect_rays);
    EXPECT_EQ(got.refract_rays, want.refract_rays);
    EXPECT_EQ(got.shadow_rays, want.shadow_rays);
}

class RenderIdentity : public ::testing::TestWithParam<const char*> {};

TEST_P(RenderIdentity, SamePixelsAndCountsAsTheRecursiveTracer) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam() + ".nff");
    const auto accel = build_accel(scene, accel_config("bvh4"));
    WhittedOptions options;
    options.width = 150;  // not a multiple of the tiles or the 4 x 4 blocks
    options.height = 110;
    for (int packet : {1, 16}) {
        if (!accel->supports_packet(packet)) continue;
        options.packet = packet;
        // Tiles of render_tiles' choice (balls and rings: 64, their
        // reflections in streams where the build has them) and of 16.
        for (int tile : {0, 16}) {
            options.tile_size = tile;
            SCOPED_TRACE("packet " + std::to_string(packet) + " tile " + std::to_string(tile));
            expect_same_render(scene, *accel, options);
        }
    }
}

// Streams carry reflections only where most of the scene is curved mirrors.
TEST(RenderTiles, LargerTilesWhereStreamsCarryTheReflections) {
    WhittedOptions options;
    for (const char* name : {"balls", "gears", "mount", "rings", "teapot", "tetra", "tree"}) {
        const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + name + ".nff");
        const auto accel = build_accel(scene, accel_config("bvh4"));
        const bool curved = std::string(name) == "balls" || std::string(name) == "rings";
        SCOPED_TRACE(name);
        EXPECT_EQ(render_tiles(scene, options, *accel, true).tile, curved && accel->supports_stream() ? 64 : 16);
        EXPECT_EQ(render_tiles(scene, options, *accel, false).tile, 16);
        options.tile_size = 8;
        EXPECT_EQ(render_tiles(scene, options, *accel, true).tile, 8);
        options.tile_size = 0;
    }
}

INSTANTIATE_TEST_SUITE_P(SpdScenes, RenderIdentity,
                         ::testing::Values("balls", "gears", "mount", "rings", "teapot", "tetra", "tree"));

TEST(RenderIdentity, DepthsOffsetsAndStructures) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/gears.nff");  // reflect + refract
    WhittedOptions options;
    options.width = 64;
    options.height = 48;
    for (const char* kind : {"bvh2", "bvh8", "grid"}) {
        const auto accel = build_accel(scene, accel_config(kind));
        for (int depth : {1, 2, 3, 9})
            for (OffsetPolicy offset : {OffsetPolicy::Epsilon, OffsetPolicy::Scaled, OffsetPolicy::Robust}) {
                SCOPED_TRACE(std::string(kind) + " depth " + std::to_string(depth) + " offset " +
                             offset_policy_name(offset));
                options.max_depth = depth;
                options.offset = offset;
                options.packet = accel->supports_packet(8) ? 8 : 1;
                expect_same_render(scene, *accel, options);
            }
    }
}

TEST(RenderIdentity, WholeSpdImageOfBalls) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/balls.nff");
    const auto accel = build_accel(scene, accel_config("bvh4"));
    WhittedOptions options;  // 512 x 512, depth 5
    options.packet = accel->supports_packet(16) ? 16 : 1;
    expect_same_render(scene, *accel, options);
}

}  // namespace
}  // namespace raypack
