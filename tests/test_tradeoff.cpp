// The accuracy measures of `raypack bench --tradeoff` (render/accuracy_measures.h)
// and the bench itself: the watertight test leaks nowhere on a million rays
// at shared edges and vertices, the measures tell a leaking kernel from a
// tight one, and the quick run writes every documented column.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "accel/accel.h"
#include "render/accuracy_measures.h"
#include "render/closed_meshes.h"

namespace raypack {
namespace {

namespace fs = std::filesystem;

LeakCounts mesh_leaks(TriangleMethod method, std::uint64_t rays) {
    static const ObjectScene meshes = leak_test_meshes(0, 3);
    const auto accel = build_accel(meshes.scene, accel_config("bvh2", KernelChoice{.sphere = SphereMethod::Geometric, .triangle = method}));
    return count_mesh_leaks(meshes, *accel, rays);
}

TEST(Tradeoff, WatertightLeaksNowhereOnAMillionEdgeAndVertexRays) {
    const LeakCounts c = mesh_leaks(TriangleMethod::Watertight, 1'000'000);
    EXPECT_GE(c.rays(), 1'000'000u);
    EXPECT_GT(c.vertex_rays, 300'000u);
    EXPECT_GT(c.edge_rays, 300'000u);
    EXPECT_GT(c.inside_rays, 200'000u);
    EXPECT_EQ(c.vertex_leaks, 0u);
    EXPECT_EQ(c.edge_leaks, 0u);
    EXPECT_EQ(c.inside_leaks, 0u);
}

TEST(Tradeoff, MoellerTrumboreLeaksAtSharedVertices) {
    // Measured, not assumed: Moeller-Trumbore's edge tests round differently
    // in the triangles around a vertex, so some rays pass between them.
    const LeakCounts c = mesh_leaks(TriangleMethod::Moeller, 200'000);
    std::printf("moeller leaks: vertex %llu/%llu, edge %llu/%llu, inside %llu/%llu\n",
                (unsigned long long)c.vertex_leaks, (unsigned long long)c.vertex_rays,
                (unsigned long long)c.edge_leaks, (unsigned long long)c.edge_rays,
                (unsigned long long)c.inside_leaks, (unsigned long long)c.inside_rays);
    EXPECT_GT(c.vertex_leaks, 0u);
}

TEST(Tradeoff, LeakMeasureIsTheSameForEveryStructure) {
    // The brute-force oracle and the BVH see the same leaks: they come from
    // the triangle test, not from traversal.
    const ObjectScene meshes = leak_test_meshes(0, 2);
    const KernelChoice moeller{.triangle = TriangleMethod::Moeller};
    const LeakCounts brute =
        count_mesh_leaks(meshes, *build_accel(meshes.scene, accel_config("brute", moeller)), 20000);
    const LeakCounts bvh = count_mesh_leaks(meshes, *build_accel(meshes.scene, accel_config("bvh2", moeller)), 20000);
    EXPECT_EQ(brute.leaks(), bvh.leaks());
    EXPECT_EQ(brute.rays(), bvh.rays());
}

TEST(Tradeoff, PreciseSphereTestHasNoLeakFromInside) {
    const ObjectScene spheres = leak_test_spheres();
    const auto accel = build_accel(spheres.scene, accel_config("bvh2", KernelChoice{.sphere = SphereMethod::Precise, .triangle = TriangleMethod::Moeller}));
    const LeakCounts c = count_sphere_leaks(spheres, *accel, 200'000);
    EXPECT_EQ(c.inside_rays, 200'000u);
    EXPECT_EQ(c.inside_leaks, 0u);
}

TEST(Tradeoff, UlpErrorSeparatesTheAlgebraicSphereTest) {
    // Small spheres seen from far away: the algebraic discriminant cancels
    // (Haines et al., Ray Tracing Gems ch. 7), the geometric form does not.
    const Scene& scene = leak_test_spheres().scene;
    const UlpError algebraic = t_error_ulps(scene, PrimKind::Sphere, {.sphere = SphereMethod::Algebraic}, 20000);
    const UlpError precise = t_error_ulps(scene, PrimKind::Sphere, {.sphere = SphereMethod::Precise}, 20000);
    EXPECT_GT(precise.rays, 15000u);
    EXPECT_LE(precise.median, 2);
    EXPECT_GT(algebraic.p99, 10 * std::max(1.0, precise.p99));
}

TEST(Tradeoff, ImageErrorOfIdenticalAndOfOnePixelChangedImages) {
    Image a(4, 4), b(4, 4);
    for (float& v : a.rgb) v = 0.5f;
    b = a;
    ImageError same = image_error(a, b);
    EXPECT_TRUE(std::isinf(same.psnr_db));
    EXPECT_EQ(same.differing_fraction, 0);
    b.set(1, 2, {0.5f, 0.5f, 0.6f});
    const ImageError one = image_error(a, b);
    EXPECT_DOUBLE_EQ(one.differing_fraction, 1.0 / 16);
    EXPECT_NEAR(one.psnr_db, 10 * std::log10(48 / 0.01), 1e-3);  // MSE 0.01 / 48 channels
}

TEST(Tradeoff, DoubleReferenceRenderAgreesWithTheFloatRenderOnAPlainScene) {
    const ObjectScene s = mixed_convex_scene(1, Vec3f{});
    WhittedOptions options;
    options.width = options.height = 32;
    Image test;
    render_whitted(s.scene, *build_accel(s.scene, AccelConfig{}), options, test);
    const ImageError e = image_error(test, render_double_reference(s.scene, options));
    EXPECT_GT(e.psnr_db, 40);
    EXPECT_LT(e.differing_fraction, 0.05);
}

/// `raypack bench --tradeoff --quick`: the CI run of the trade table.
TEST(Tradeoff, QuickBenchWritesTheSchemaAndMeetsTheTargets) {
    const fs::path dir = fs::temp_directory_path() / "raypack_test_tradeoff";
    fs::create_directories(dir);
    const fs::path json = dir / "t.json", csv = dir / "t.csv", log = dir / "t.log";
    const std::string command = std::string(RAYPACK_CLI) + " bench --tradeoff --quick --repeat 1 --json " +
                                json.string() + " --csv " + csv.string() + " >" + log.string() + " 2>&1";
    const int raw = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << command;
    std::ifstream in(json);
    const nlohmann::json rows = nlohmann::json::parse(in);
    ASSERT_EQ(rows.size(), 9u);
    const char* const fields[] = {"family", "variant", "throughput_scene", "throughput_rays", "timed_rays",
                                  "mrays_per_s_median", "leak_rays", "leaks", "leak_fraction", "leak_vertex",
                                  "leak_edge", "leak_inside", "t_ulp_rays", "t_ulp_median", "t_ulp_p99", "t_ulp_max",
                                  "self_rays", "self_hits", "self_fraction", "self_shadow_hits_s1e-04",
                                  "self_reflect_hits_s1e+06", "shadow_wrong_t1e+06", "image_scene", "psnr_db",
                                  "differing_fraction"};
    for (const auto& row : rows)
        for (const char* f : fields) EXPECT_TRUE(row.contains(f)) << f;
    std::ifstream csv_in(csv);
    std::string header;
    std::getline(csv_in, header);
    EXPECT_EQ(header.rfind("family,variant,throughput_scene,", 0), 0u) << header;
    bool saw_watertight = false, saw_robust = false, saw_moeller = false;
    for (const auto& row : rows) {
        if (row["variant"] == "watertight") {
            saw_watertight = true;
            EXPECT_GE(row["leak_rays"].get<std::uint64_t>(), 1'000'000u);
            EXPECT_EQ(row["leaks"].get<std::uint64_t>(), 0u);
        }
        if (row["variant"] == "moeller") {
            saw_moeller = true;
            EXPECT_GT(row["leaks"].get<std::uint64_t>(), 0u);
        }
        if (row["variant"] == "robust") {
            saw_robust = true;
            EXPECT_GT(row["self_rays"].get<std::uint64_t>(), 0u);
            for (const auto& [key, value] : row.items()) {
                if (key.rfind("self_shadow_hits_", 0) == 0 || key.rfind("self_reflect_hits_", 0) == 0) {
                    EXPECT_EQ(value.get<std::uint64_t>(), 0u) << key;
                }
            }
        }
        EXPECT_GT(row["mrays_per_s_median"].get<double>(), 0);
    }
    EXPECT_TRUE(saw_watertight && saw_robust && saw_moeller);
}

TEST(Tradeoff, OptionsThatDoNotApplyAreRefused) {
    const int raw = std::system((std::string(RAYPACK_CLI) + " bench --tradeoff --accel grid >/dev/null 2>&1").c_str());
    EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) != 0);
    const int bad = std::system((std::string(RAYPACK_CLI) + " render gen:balls:1 --offset tiny >/dev/null 2>&1").c_str());
    EXPECT_TRUE(WIFEXITED(bad) && WEXITSTATUS(bad) != 0);
}

}  // namespace
}  // namespace raypack
