// Packet traversal of the BVH2 against its single-ray traversal: the same
// kernels run per lane, so hits must be identical, bit for bit, for every
// width, every kernel variant, closest hit and occlusion.
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <bit>
#include <random>

#include "accel/accel.h"
#include "measure/ray_sets.h"
#include "scene/load.h"

namespace raypack {
namespace {

std::vector<Rayf> mixed_rays(const Scene& scene) {
    std::vector<Rayf> rays = camera_ray_set(scene, 48, 48);
    // Incoherent rays too: random origins in the scene box, random directions,
    // so packets diverge and lanes finish at different depths.
    const Box3f b = scene_bounds(scene);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), d(-1.0f, 1.0f);
    for (int i = 0; i < 1500; ++i) {
        Rayf r;
        r.org = {b.lo.x + u(rng) * (b.hi.x - b.lo.x), b.lo.y + u(rng) * (b.hi.y - b.lo.y),
                 b.lo.z + u(rng) * (b.hi.z - b.lo.z)};
        r.dir = {d(rng), d(rng), d(rng)};
        if (i % 7 == 0) r.dir.y = (i % 2) ? 0.0f : -0.0f;  // axis-parallel components
        r.tfar = (i % 5 == 0) ? 0.5f * length(b.extent()) : std::numeric_limits<float>::infinity();
        rays.push_back(r);
    }
    rays.resize(rays.size() - 3);  // a ragged last packet
    return rays;
}

class Bvh2Packet : public ::testing::TestWithParam<const char*> {};

TEST_P(Bvh2Packet, EqualsSingleRayTraversal) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    const std::vector<Rayf> rays = mixed_rays(scene);
    const std::vector<Rayf> shadows = shadow_ray_set(scene, 40, 40);
    const KernelChoice variants[] = {
        {SphereMethod::Geometric, TriangleMethod::Moeller},
        {SphereMethod::Algebraic, TriangleMethod::Watertight},
        {SphereMethod::Precise, TriangleMethod::Plane},
    };
    for (const KernelChoice& kc : variants) {
        AccelConfig config;
        config.kernels = kc;
        const auto bvh = build_accel(scene, config);
        std::vector<Hitf> want(rays.size());
        bvh->intersect(rays, want);
        std::vector<std::uint8_t> want_occ(shadows.size());
        bvh->occluded(shadows, want_occ);
        for (int width : {4, 8, 16}) {
            if (!bvh->supports_packet(width)) continue;
            SCOPED_TRACE(::testing::Message() << "width " << width << " sphere " << int(kc.sphere) << " triangle "
                                              << int(kc.triangle));
            std::vector<Hitf> got(rays.size());
            bvh->intersect_packets(width, rays, got);
            int differ = 0;
            for (std::size_t i = 0; i < rays.size(); ++i) {
                const bool same = got[i].prim == want[i].prim &&
                                  std::bit_cast<std::uint32_t>(got[i].t) == std::bit_cast<std::uint32_t>(want[i].t) &&
                                  (!want[i].found() || (std::bit_cast<std::uint32_t>(got[i].u) ==
                                                            std::bit_cast<std::uint32_t>(want[i].u) &&
                                                        std::bit_cast<std::uint32_t>(got[i].v) ==
                                                            std::bit_cast<std::uint32_t>(want[i].v)));
                if (!same && ++differ <= 3)
                    ADD_FAILURE() << "ray " << i << ": single prim " << want[i].prim << " t " << want[i].t
                                  << ", packet prim " << got[i].prim << " t " << got[i].t;
            }
            EXPECT_EQ(differ, 0);
            std::vector<std::uint8_t> occ(shadows.size());
            bvh->occluded_packets(width, shadows, occ);
            EXPECT_EQ(occ, want_occ);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(SharedScenes, Bvh2Packet,
                         ::testing::Values("balls.nff", "gears.nff", "mount.nff", "rings.nff", "teapot.nff",
                                           "tetra.nff", "tree.nff"),
                         [](const auto& test_info) {
                             std::string name = test_info.param;
                             return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace raypack
