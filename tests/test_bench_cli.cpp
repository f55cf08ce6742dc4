// raypack bench: the CI run (--quick) must finish, validate every row and
// write JSON and CSV with the documented columns; bad input is answered
// with a message and a non-zero status.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <iterator>

#include "accel/accel.h"

namespace raypack {
namespace {

namespace fs = std::filesystem;

/// One directory per test: ctest runs the tests of this file in parallel,
/// and a shared bench.log let one test read another's output.
fs::path temp_dir() {
    const fs::path d = fs::temp_directory_path() / "raypack_test_bench_cli" /
                       ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(d);
    return d;
}

/// Exit status of `raypack bench ARGS` and what it printed (both streams).
struct BenchRun {
    int status = -1;
    std::string output;
};

BenchRun run_bench(const std::string& args) {
    const fs::path log = temp_dir() / "bench.log";
    const int raw = std::system((std::string(RAYPACK_CLI) + " bench " + args + " >" + log.string() + " 2>&1").c_str());
    BenchRun run;
    run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    std::ifstream in(log);
    run.output.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return run;
}

std::string first_line(const fs::path& p) {
    std::ifstream in(p);
    std::string line;
    std::getline(in, line);
    return line;
}

const char* const kRequiredFields[] = {"scene",           "accel",           "packet",       "rays",
                                       "threads",         "build_ms",        "mrays_per_s_median",
                                       "mrays_per_s_min", "mrays_per_s_max", "n_it",
                                       "n_ts",            "n_ets",           "n_eets",       "memory_bytes",
                                       "validated"};

TEST(BenchCli, ReportIsOneSelfContainedPageThatABrowserRenders) {
    // `--report`: one HTML file, nothing fetched from anywhere (every picture
    // a data URI, no scripts or styles from files), its tables and one cost
    // map per counting structure; then Debian's chromium (installed by
    // scripts/setup) opens it headless and every picture must decode.
    const fs::path html = temp_dir() / "report.html";
    fs::remove(html);
    const std::string scene = std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff";
    const BenchRun run = run_bench(scene + " --accel bvh2,grid,octree --packet 1 --rays camera,shadow --res 24 24" +
                                   " --repeat 1 --report " + html.string());
    ASSERT_EQ(run.status, 0) << run.output;
    std::ifstream in(html);
    const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto count = [&](const std::string& what) {
        std::size_t n = 0;
        for (std::size_t at = page.find(what); at != std::string::npos; at = page.find(what, at + 1)) ++n;
        return n;
    };
    EXPECT_EQ(page.rfind("<!doctype html>", 0), 0u);
    EXPECT_EQ(count("<img"), 3u);  // bvh2, grid, octree
    EXPECT_EQ(count("src=\"data:image/bmp;base64,"), 3u);
    EXPECT_EQ(count("src="), 3u);  // nothing else to load
    EXPECT_EQ(count("http"), 0u);
    EXPECT_EQ(count("<table class=\"best\">"), 2u);  // camera and shadow rays
    EXPECT_EQ(count("<svg"), 2u);
    EXPECT_EQ(count("<table class=\"havran\">"), 1u);
    // Havran and Sixta's uniform grid and octree on teapot.
    EXPECT_NE(page.find("13.30 / 41.24 / 41.24 / 38.08"), std::string::npos);
    EXPECT_NE(page.find("40.02 / 83.40 / 13.75 / 9.53"), std::string::npos);
    const fs::path dom = temp_dir() / "dom.html";
    // A profile of its own: CI runs as root, perhaps without a writable home.
    const std::string browser = "chromium --headless --no-sandbox --disable-gpu --user-data-dir=" +
                                (temp_dir() / "profile").string() + " --dump-dom file://" + html.string() + " >" +
                                dom.string() + " 2>/dev/null";
    ASSERT_EQ(std::system("command -v chromium >/dev/null"), 0) << "chromium is missing (scripts/setup installs it)";
    ASSERT_EQ(std::system(("timeout 120 " + browser).c_str()), 0);
    std::ifstream dumped(dom);
    const std::string rendered((std::istreambuf_iterator<char>(dumped)), std::istreambuf_iterator<char>());
    EXPECT_NE(rendered.find("data-images-ok=\"3/3\""), std::string::npos) << rendered.substr(0, 400);
    EXPECT_NE(rendered.find("<table class=\"rows\">"), std::string::npos);
}

TEST(BenchCli, QuickRunValidatesEveryStructureWidthAndRayKind) {
    const fs::path json = temp_dir() / "quick.json", csv = temp_dir() / "quick.csv";
    fs::remove(json);
    fs::remove(csv);
    const BenchRun r = run_bench("--quick --json " + json.string() + " --csv " + csv.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("elapsed"), std::string::npos) << "progress lines on stderr";

    std::ifstream in(json);
    const nlohmann::json rows = nlohmann::json::parse(in);
    ASSERT_TRUE(rows.is_array());
    std::set<std::string> accels, kinds;
    std::set<std::pair<std::string, int>> widths;
    for (const auto& row : rows) {
        for (const char* field : kRequiredFields) ASSERT_TRUE(row.contains(field)) << field << " in " << row.dump();
        EXPECT_EQ(row["validated"], true) << row.dump();
        EXPECT_GT(row["mrays_per_s_median"].get<double>(), 0.0) << row.dump();
        EXPECT_LE(row["mrays_per_s_min"].get<double>(), row["mrays_per_s_median"].get<double>()) << row.dump();
        EXPECT_LE(row["mrays_per_s_median"].get<double>(), row["mrays_per_s_max"].get<double>()) << row.dump();
        const std::string accel = row["accel"];
        if (is_embree_kind(accel)) {
            for (const char* m : {"n_it", "n_ts", "n_ets", "n_eets"}) EXPECT_TRUE(row[m].is_null()) << "Embree cannot count";
        } else if (accel != "brute") {
            // Havran's measures: every elementary cell is a traversal step,
            // empty cells are elementary cells; a BVH has no empty leaves,
            // and a grid's traversal steps are its cells.
            const double it = row["n_it"], ts = row["n_ts"], ets = row["n_ets"], eets = row["n_eets"];
            EXPECT_GT(it, 0.0) << row.dump();
            EXPECT_GT(ets, 0.0) << row.dump();
            EXPECT_LE(ets, ts) << row.dump();
            EXPECT_LE(eets, ets) << row.dump();
            if (accel.rfind("bvh", 0) == 0) {
                EXPECT_EQ(eets, 0.0) << row.dump();
            }
            if (accel == "grid") {
                EXPECT_EQ(ets, ts) << row.dump();
                EXPECT_GT(eets, 0.0) << "the SPD balls grid has empty cells on every ray kind: " << row.dump();
            }
        }
        accels.insert(accel);
        kinds.insert(row["rays"].get<std::string>());
        widths.insert({accel, row["packet"].get<int>()});
    }
    for (const char* k : accel_kinds()) EXPECT_TRUE(accels.count(k)) << "no rows for " << k;
    EXPECT_EQ(kinds, (std::set<std::string>{"camera", "shadow", "diffuse"}));
    EXPECT_TRUE(widths.count({"bvh2", 4})) << "bvh2 packets of 4 missing";
    EXPECT_EQ(rows.size() % 3, 0u) << "every (accel, width) for every ray kind";

    const std::string header = first_line(csv);
    for (const char* field : kRequiredFields) EXPECT_NE(header.find(field), std::string::npos) << field;
    std::ifstream csv_in(csv);
    std::size_t lines = 0;
    for (std::string line; std::getline(csv_in, line);) ++lines;
    EXPECT_EQ(lines, rows.size() + 1);
}

TEST(BenchCli, BadFlagsAreUsageErrors) {
    for (const char* args : {"--accel nosuch", "--packet 3", "--rays camera,sideways", "--repeat 0", "--threads x",
                             "--res 10", "--bogus", "--rays camera --rays-file x.rays"}) {
        const BenchRun r = run_bench(args);
        EXPECT_EQ(r.status, 2) << args << ": " << r.output;
        EXPECT_NE(r.output.find("raypack bench"), std::string::npos) << args << ": " << r.output;
    }
}

TEST(BenchCli, MissingFilesNameTheFile) {
    const BenchRun scene = run_bench("/nonexistent/scene.nff --accel bvh2 --rays camera --res 8 8");
    EXPECT_EQ(scene.status, 1);
    EXPECT_NE(scene.output.find("/nonexistent/scene.nff"), std::string::npos) << scene.output;
    const BenchRun rays = run_bench("gen:balls:1 --rays-file /nonexistent/x.rays --accel bvh2");
    EXPECT_EQ(rays.status, 1);
    EXPECT_NE(rays.output.find("/nonexistent/x.rays"), std::string::npos) << rays.output;
    const BenchRun out = run_bench("gen:balls:1 --accel bvh2 --rays camera --res 8 8 --repeat 1 --json /nonexistent/dir/x.json");
    EXPECT_EQ(out.status, 1);
    EXPECT_NE(out.output.find("/nonexistent/dir/x.json"), std::string::npos) << out.output;
}

TEST(BenchCli, RaysFileIsTracedAndValidated) {
    const fs::path rays = temp_dir() / "camera.rays";
    const std::string make = std::string(RAYPACK_CLI) + " rays gen:balls:2 --kind diffuse --res 32 32 -o " + rays.string();
    ASSERT_EQ(std::system(make.c_str()), 0);
    const fs::path json = temp_dir() / "file.json";
    const BenchRun r = run_bench("gen:balls:2 --rays-file " + rays.string() + " --accel bvh2,grid --repeat 1 --json " +
                               json.string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(json);
    const nlohmann::json rows = nlohmann::json::parse(in);
    ASSERT_FALSE(rows.empty());
    for (const auto& row : rows) EXPECT_EQ(row["rays"], "file:camera");
}

/// The kernel variants and --builder reach the structures (the builder shows
/// in the rows) and the oracle: with watertight triangles in double, every
/// structure must still find what brute force with those tests finds, and
/// Embree, which runs its own tests, what the default oracle finds.
TEST(BenchCli, KernelVariantsAndBuilderReachStructuresAndOracle) {
    std::string accels = "bvh2,bvh8,kdtree";
    for (const char* k : accel_kinds())
        if (is_embree_kind(k)) accels += "," + std::string(k);
    const fs::path json = temp_dir() / "variants.json";
    const BenchRun r = run_bench("gen:tetra:3 --quick --rays camera,shadow --accel " + accels +
                                 " --triangle watertight --precision double --builder sweep --json " + json.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("kernels: watertight triangles, geometric spheres, robust slabs, exact rcp, double; "
                            "builder sweep"),
              std::string::npos)
        << r.output;
    std::ifstream in(json);
    const nlohmann::json rows = nlohmann::json::parse(in);
    int bvh_rows = 0;
    for (const auto& row : rows)
        if (row["accel"] == "bvh2" || row["accel"] == "bvh8") {
            EXPECT_EQ(row["builder"], "sweep") << row.dump();
            ++bvh_rows;
        }
    EXPECT_GT(bvh_rows, 0);
}

}  // namespace
}  // namespace raypack
