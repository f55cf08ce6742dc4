// The accuracy measures of `raypack bench --tradeoff` (measure/accuracy_measures.h)
// and the bench itself: the watertight test leaks nowhere on a million rays
// at shared edges and vertices, the measures tell a leaking kernel from a
// tight one, double-precision tests round t once, and the quick run covers
// every family (triangle, sphere, slabs, rcp, precision, builder, offset)
// and writes every documented column.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "measure/accuracy_measures.h"
#include "measure/closed_meshes.h"

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

TEST(Tradeoff, DoublePrecisionTrianglesAreWithinAnUlp) {
    // --precision double runs Moeller-Trumbore on the float inputs in
    // double: t is then the reference's up to the final rounding.
    const ObjectScene mixed = mixed_convex_scene(1e3f, Vec3f{});
    const Scene& scene = mixed.scene;
    const KernelChoice in_float{.triangle = TriangleMethod::Moeller};
    KernelChoice in_double = in_float;
    in_double.precision = Precision::Double;
    const UlpError f = t_error_ulps(scene, PrimKind::Triangle, in_float, 20000);
    const UlpError d = t_error_ulps(scene, PrimKind::Triangle, in_double, 20000);
    EXPECT_GT(d.rays, 15000u);
    EXPECT_LE(d.max, 1);
    EXPECT_GT(f.max, d.max);
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
    // Every family, variant and structure, once each, in this order.
    std::vector<std::string> expected;
    for (const char* v : {"moeller", "watertight", "plane"}) expected.push_back(std::string("triangle ") + v + " bvh2");
    for (const char* v : {"algebraic", "geometric", "precise"}) expected.push_back(std::string("sphere ") + v + " bvh2");
    for (const char* s : {"bvh2", "bvh8"})
        for (const char* v : {"plain", "robust"}) expected.push_back(std::string("slabs ") + v + " " + s);
    for (const char* s : {"bvh2", "bvh8"})
        for (const char* v : {"exact", "approx"}) expected.push_back(std::string("rcp ") + v + " " + s);
    for (const char* v : {"float", "double"}) expected.push_back(std::string("precision ") + v + " bvh2");
    for (const char* v : {"binned", "sweep", "morton", "sbvh"}) expected.push_back(std::string("builder ") + v + " bvh2");
    for (const char* v : {"epsilon", "scaled", "robust"}) expected.push_back(std::string("offset ") + v + " bvh2");
    std::vector<std::string> seen;
    for (const auto& row : rows)
        seen.push_back(row["family"].get<std::string>() + " " + row["variant"].get<std::string>() + " " +
                       row["structure"].get<std::string>());
    ASSERT_EQ(seen, expected);
    const char* const fields[] = {"family", "variant", "throughput_scene", "throughput_rays", "timed_rays",
                                  "mrays_per_s_median", "leak_rays", "leaks", "leak_fraction", "leak_vertex",
                                  "leak_edge", "leak_inside", "t_ulp_rays", "t_ulp_median", "t_ulp_p99", "t_ulp_max",
                                  "self_rays", "self_hits", "self_fraction", "self_shadow_hits_s1e-04",
                                  "self_reflect_hits_s1e+06", "shadow_wrong_t1e+06", "image_scene", "psnr_db",
                                  "differing_fraction", "structure", "builder", "kernels", "build_ms", "sah_cost"};
    for (const auto& row : rows)
        for (const char* f : fields) EXPECT_TRUE(row.contains(f)) << f;
    std::ifstream csv_in(csv);
    std::string header;
    std::getline(csv_in, header);
    EXPECT_EQ(header.rfind("family,variant,throughput_scene,", 0), 0u) << header;
    // Every line has the header's columns: the kernel summaries hold commas
    // and must come quoted.
    auto csv_fields = [](const std::string& line) {
        std::size_t count = 1;
        bool quoted = false;
        for (char c : line) {
            if (c == '"') quoted = !quoted;
            count += c == ',' && !quoted;
        }
        return count;
    };
    std::size_t lines = 0;
    for (std::string line; std::getline(csv_in, line); ++lines)
        EXPECT_EQ(csv_fields(line), csv_fields(header)) << line;
    EXPECT_EQ(lines, rows.size());
    const std::string tail = ",structure,builder,kernels,build_ms,sah_cost";
    EXPECT_TRUE(header.size() > tail.size() && header.compare(header.size() - tail.size(), tail.size(), tail) == 0)
        << header;
    auto find = [&](const std::string& family, const std::string& variant, const std::string& structure = "bvh2") {
        for (const auto& row : rows)
            if (row["family"] == family && row["variant"] == variant && row["structure"] == structure) return row;
        ADD_FAILURE() << family << " " << variant << " " << structure;
        return nlohmann::json::object();
    };
    auto leak_tight = [](const nlohmann::json& row) {
        EXPECT_GE(row["leak_rays"].get<std::uint64_t>(), 1'000'000u) << row["family"] << " " << row["variant"];
        EXPECT_EQ(row["leaks"].get<std::uint64_t>(), 0u) << row["family"] << " " << row["variant"] << " "
                                                         << row["structure"];
    };
    leak_tight(find("triangle", "watertight"));
    EXPECT_GT(find("triangle", "moeller")["leaks"].get<std::uint64_t>(), 0u);
    // The criterion: watertight triangles behind robust slabs and
    // exact reciprocals leak nowhere, through either structure.
    for (const char* structure : {"bvh2", "bvh8"}) {
        leak_tight(find("slabs", "robust", structure));
        leak_tight(find("rcp", "exact", structure));
    }
    // Every builder, SBVH's clipped boxes included, keeps the meshes closed.
    for (const char* builder : {"binned", "sweep", "morton", "sbvh"}) {
        const auto row = find("builder", builder);
        leak_tight(row);
        EXPECT_EQ(row["builder"], builder);
        EXPECT_GT(row["build_ms"].get<double>(), 0);
        EXPECT_GT(row["sah_cost"].get<double>(), 0);
    }
    const auto in_float = find("precision", "float"), in_double = find("precision", "double");
    EXPECT_LE(in_double["t_ulp_max"].get<double>(), 1);
    EXPECT_LT(in_double["t_ulp_max"].get<double>(), in_float["t_ulp_max"].get<double>());
    EXPECT_NE(in_double["kernels"].get<std::string>().find("double"), std::string::npos);
    const auto robust = find("offset", "robust");
    EXPECT_GT(robust["self_rays"].get<std::uint64_t>(), 0u);
    for (const auto& [key, value] : robust.items())
        if (key.rfind("self_shadow_hits_", 0) == 0 || key.rfind("self_reflect_hits_", 0) == 0) {
            EXPECT_EQ(value.get<std::uint64_t>(), 0u) << key;
        }
    for (const auto& row : rows) {
        const std::string family = row["family"];
        EXPECT_GT(row["mrays_per_s_median"].get<double>(), 0) << family;
        EXPECT_FALSE(row["kernels"].get<std::string>().empty()) << family;
        // t comes from the primitive test alone, which these families keep.
        const bool traversal = family == "slabs" || family == "rcp" || family == "builder";
        EXPECT_EQ(row["t_ulp_max"].is_null(), traversal || family == "offset") << family;
        if (traversal) {
            EXPECT_EQ(row["kernels"].get<std::string>().rfind("watertight triangles", 0), 0u) << family;
        }
        EXPECT_EQ(row["build_ms"].is_null(), family != "builder") << family;
    }
}

TEST(Tradeoff, OptionsThatDoNotApplyAreRefused) {
    const int raw = std::system((std::string(RAYPACK_CLI) + " bench --tradeoff --accel grid >/dev/null 2>&1").c_str());
    EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) != 0);
    const int bad = std::system((std::string(RAYPACK_CLI) + " render gen:balls:1 --offset tiny >/dev/null 2>&1").c_str());
    EXPECT_TRUE(WIFEXITED(bad) && WEXITSTATUS(bad) != 0);
}

}  // namespace
}  // namespace raypack
