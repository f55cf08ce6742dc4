// The raypack command line: outputs other tools rely on, and bad input
// answered with a message and a non-zero status, never a crash or a
// half-written file.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include "kernels/simd.h"
#include <sstream>

#include "scene/ray_file.h"
#include "scene/spd/spd.h"

namespace raypack {
namespace {

namespace fs = std::filesystem;

struct Result {
    int status;
    std::string output;  // stdout and stderr together
};

Result run(const std::string& args) {
    const std::string cmd = std::string(RAYPACK_CLI) + " " + args + " 2>&1";
    FILE* pipe = popen(cmd.c_str(), "r");
    std::string out;
    std::array<char, 4096> buf;
    std::size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
    const int status = pclose(pipe);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

/// One directory per test: ctest runs these tests in parallel.
fs::path temp_dir() {
    const fs::path d = fs::temp_directory_path() / "raypack_test_cli" /
                       ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(d);
    return d;
}

std::string scene_path(const std::string& name) { return std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + name; }

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

TEST(Cli, InfoReportsCountsCameraLightsAndFeatures) {
    const Result r = run("info " + scene_path("rings.nff"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("spheres    4200"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("cones      4200"), std::string::npos);
    EXPECT_NE(r.output.find("lights: 3"), std::string::npos);
    EXPECT_NE(r.output.find("features: spheres triangles cones reflection"), std::string::npos);
}

TEST(Cli, GenReproducesTheSpdFile) {
    const fs::path out = temp_dir() / "balls.nff";
    const Result r = run("gen balls --size 4 -o " + out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(slurp(out), slurp(scene_path("balls.nff")));
}

TEST(Cli, RenderWritesTheImageAndSaysWhere) {
    const fs::path out = temp_dir() / "tetra.png";
    fs::remove(out);
    const Result r = run("render gen:tetra:3 -o " + out.string() + " --res 64 48 --depth 2 --threads 1 --packet 4");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(out));
    EXPECT_NE(r.output.find("64x48"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(out.string()), std::string::npos);
}

TEST(Cli, RenderJsonReportsTimesRaysAndThroughput) {
    const fs::path out = temp_dir() / "balls.png";
    const Result r = run("render gen:balls:2 -o " + out.string() + " --res 80 60 --threads 1 --json");
    ASSERT_EQ(r.status, 0) << r.output;
    // One line, nothing else (stdout is a pipe: no progress line either).
    ASSERT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    const nlohmann::json j = nlohmann::json::parse(r.output);
    EXPECT_EQ(j["integrator"], "whitted");
    EXPECT_EQ(j["width"], 80);
    EXPECT_EQ(j["height"], 60);
    EXPECT_EQ(j["spp"], 1);
    EXPECT_EQ(j["threads"], 1);
    for (const char* k : {"load_ms", "build_ms", "render_ms", "write_ms"}) EXPECT_GE(j[k].get<double>(), 0.0) << k;
    const auto& rays = j["rays"];
    EXPECT_EQ(rays["eye"], 80 * 60);
    EXPECT_GT(rays["shadow"].get<std::uint64_t>(), 0u);
    EXPECT_GT(rays["reflect"].get<std::uint64_t>(), 0u);  // balls: the spheres are mirrors
    EXPECT_EQ(rays["refract"], 0);
    const double total = rays["eye"].get<double>() + rays["shadow"].get<double>() + rays["reflect"].get<double>() +
                         rays["refract"].get<double>();
    EXPECT_NEAR(j["mrays_per_s"].get<double>(), total / (j["render_ms"].get<double>() * 1e3), 1e-9 * total);
    EXPECT_TRUE(fs::exists(out));
}

TEST(Cli, RenderCountsHavransMeasuresOverTheWholeRenderWithTheSameImage) {
    const fs::path plain = temp_dir() / "plain.png", counted = temp_dir() / "counted.png";
    for (const char* accel : {"bvh4", "grid", "kdtree", "octree"}) {
        const std::string common = std::string(" --res 64 48 --threads 2 --accel ") + accel;
        const Result a = run("render gen:balls:2 -o " + plain.string() + common + " --json");
        const Result b = run("render gen:balls:2 -o " + counted.string() + common + " --json --counts");
        ASSERT_EQ(a.status, 0) << a.output;
        ASSERT_EQ(b.status, 0) << b.output;
        // The counting walk answers every query as the structure does.
        EXPECT_EQ(slurp(plain), slurp(counted)) << accel;
        const nlohmann::json ja = nlohmann::json::parse(a.output), jb = nlohmann::json::parse(b.output);
        EXPECT_EQ(ja["rays"], jb["rays"]) << accel;
        EXPECT_FALSE(ja.contains("n_it"));
        const auto& r = jb["rays"];
        EXPECT_EQ(jb["counted_rays"].get<std::uint64_t>(),
                  r["eye"].get<std::uint64_t>() + r["shadow"].get<std::uint64_t>() +
                      r["reflect"].get<std::uint64_t>() + r["refract"].get<std::uint64_t>())
            << accel;
        const double it = jb["n_it"], ts = jb["n_ts"], ets = jb["n_ets"], eets = jb["n_eets"];
        EXPECT_GT(it, 0.0) << accel;
        EXPECT_GT(ets, 0.0) << accel;
        EXPECT_LE(ets, ts) << accel;
        EXPECT_LE(eets, ets) << accel;
    }
#ifdef RAYPACK_HAVE_EMBREE
    // Structures that cannot count say so.
    const Result e = run("render gen:balls:1 -o " + counted.string() + " --res 8 8 --accel embree --counts");
    EXPECT_EQ(e.status, 2) << e.output;
    EXPECT_NE(e.output.find("--counts: embree cannot count"), std::string::npos) << e.output;
#endif
    const Result m = run("render gen:balls:1:motion -o " + counted.string() + " --res 8 8 --counts");
    EXPECT_EQ(m.status, 2) << m.output;
    EXPECT_NE(m.output.find("--counts: a moving scene"), std::string::npos) << m.output;
}

/// --save-rays writes every ray of the render by kind: as many as the
/// render counts, of the right query, and the render's image unchanged.
TEST(Cli, RenderSavesTheRaysItTracedByKind) {
    const fs::path dir = temp_dir(), plain = dir / "plain.png", saving = dir / "saving.png";
    const std::string prefix = (dir / "balls").string();
    const std::string common = " --res 64 48 --threads 2 --json";
    const Result a = run("render gen:balls:2 -o " + plain.string() + common);
    const Result b = run("render gen:balls:2 -o " + saving.string() + common + " --save-rays " + prefix);
    ASSERT_EQ(a.status, 0) << a.output;
    ASSERT_EQ(b.status, 0) << b.output;
    EXPECT_EQ(slurp(plain), slurp(saving));
    const nlohmann::json j = nlohmann::json::parse(b.output);
    const auto& r = j["rays"];
    ASSERT_EQ(j["saved_rays"].size(), 3u) << b.output;
    const RayFile eye = read_rays(prefix + "-eye.rays"), bounce = read_rays(prefix + "-bounce.rays"),
                  shadow = read_rays(prefix + "-shadow.rays");
    EXPECT_EQ(eye.kind, RayKind::ClosestHit);
    EXPECT_EQ(bounce.kind, RayKind::ClosestHit);
    EXPECT_EQ(shadow.kind, RayKind::AnyHit);
    EXPECT_EQ(eye.rays.size(), r["eye"].get<std::size_t>());
    EXPECT_EQ(bounce.rays.size(), r["reflect"].get<std::size_t>() + r["refract"].get<std::size_t>());
    EXPECT_EQ(shadow.rays.size(), r["shadow"].get<std::size_t>());
    EXPECT_TRUE(eye.times.empty());
    // The eye rays leave the pinhole, and trace finds the hits the render counted.
    for (const Rayf& ray : eye.rays) ASSERT_EQ(ray.org, eye.rays[0].org);
    const Result t = run("trace gen:balls:2 --rays " + prefix + "-eye.rays --repeat 1 --json");
    ASSERT_EQ(t.status, 0) << t.output;
    EXPECT_EQ(nlohmann::json::parse(t.output)["hits"], r["eye_hits"]);

    // Path tracing a moving scene: diffuse bounces, and every ray's time.
    const Result m = run("render gen:balls:1:motion -o " + saving.string() +
                         " --res 16 16 --integrator path --spp 2 --depth 3 --json --save-rays " + prefix + "-m");
    ASSERT_EQ(m.status, 0) << m.output;
    const nlohmann::json jm = nlohmann::json::parse(m.output);
    const auto& mr = jm["rays"];
    std::size_t saved = 0;
    for (const char* kind : {"-m-eye.rays", "-m-bounce.rays", "-m-shadow.rays"}) {
        const RayFile f = read_rays(prefix + kind);
        ASSERT_EQ(f.times.size(), f.rays.size()) << kind;
        for (const float time : f.times) ASSERT_TRUE(time >= 0.0f && time <= 1.0f) << kind;  // gen's shutter
        saved += f.rays.size();
    }
    EXPECT_EQ(saved, mr["eye"].get<std::size_t>() + mr["shadow"].get<std::size_t>() +
                         mr["reflect"].get<std::size_t>() + mr["refract"].get<std::size_t>() +
                         mr["diffuse"].get<std::size_t>());
    EXPECT_GT(mr["diffuse"].get<std::size_t>(), 0u);
}

TEST(Cli, RenderQuietPrintsNothing) {
    const fs::path out = temp_dir() / "tetra.png";
    fs::remove(out);
    const Result r = run("render gen:tetra:3 -o " + out.string() + " --res 32 32 --quiet");
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.output, "");
    EXPECT_TRUE(fs::exists(out));
}

TEST(Cli, TraceAnswersClosestAndAnyHitWithJson) {
    const fs::path dir = temp_dir();
    const std::string scene = "gen:balls:2";
    ASSERT_EQ(run("rays " + scene + " --kind camera --res 32 32 -o " + (dir / "c.rays").string()).status, 0);
    ASSERT_EQ(run("rays " + scene + " --kind shadow --res 32 32 -o " + (dir / "s.rays").string()).status, 0);
    for (const char* kind : {"c", "s"}) {
        const std::string rays = (dir / (std::string(kind) + ".rays")).string();
        const std::string hits = (dir / (std::string(kind) + ".hits")).string();
        const Result r = run("trace " + scene + " --rays " + rays + " -o " + hits + " --repeat 3 --threads 2 --json");
        ASSERT_EQ(r.status, 0) << r.output;
        const auto j = nlohmann::json::parse(r.output);
        for (const char* key : {"rays", "build_ms", "trace_ms_median", "mrays_per_s_median", "hits"})
            EXPECT_TRUE(j.contains(key)) << key;
        const RayFile file = read_rays(rays);
        const auto h = read_hits(hits);
        ASSERT_EQ(h.size(), file.rays.size());
        EXPECT_EQ(j["rays"].get<std::size_t>(), file.rays.size());
        std::size_t found = 0;
        for (const auto& x : h) found += x.found();
        EXPECT_EQ(j["hits"].get<std::size_t>(), found);
        if (file.kind == RayKind::ClosestHit) EXPECT_EQ(found, file.rays.size());  // balls: every eye ray hits
        else EXPECT_GT(found, 0u);  // some points are in shadow
    }
}

/// trace --stream (bvh4 and bvh8 with AVX-512): the same answers as packets
/// (hits at the same t; the primitive may differ only between coincident
/// hits); a structure without streams is a usage error.
TEST(Cli, TraceStreamAnswersAsPacketsDo) {
    const fs::path dir = temp_dir();
    const std::string scene = "gen:balls:2";
    const std::string base = "trace " + scene + " --repeat 1 --threads 2 --accel bvh4 --packet 16";
    for (const char* kind : {"diffuse", "shadow"}) {
        const std::string rays = (dir / (std::string(kind) + ".rays")).string();
        ASSERT_EQ(run("rays " + scene + " --kind " + kind + " --res 80 80 -o " + rays).status, 0);
        const std::string packets = (dir / (std::string(kind) + "-packets.hits")).string();
        const std::string stream = (dir / (std::string(kind) + "-stream.hits")).string();
        ASSERT_EQ(run(base + " --rays " + rays + " -o " + packets).status, 0);
        const Result r = run(base + " --rays " + rays + " -o " + stream + " --stream --json");
        if (r.status == 2 && r.output.find("no stream traversal") != std::string::npos)
            GTEST_SKIP() << "this build has no streams (AVX-512)";
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_TRUE(nlohmann::json::parse(r.output)["stream"].get<bool>());
        const auto a = read_hits(packets), b = read_hits(stream);
        ASSERT_EQ(a.size(), b.size());
        std::size_t differ = 0, found = 0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            found += a[i].found();
            differ += a[i].found() != b[i].found() || (a[i].found() && std::string(kind) == "diffuse" && a[i].t != b[i].t);
        }
        EXPECT_EQ(differ, 0u) << kind;
        EXPECT_GT(found, 0u) << kind;
    }
    const Result grid = run("trace " + scene + " --rays " + (dir / "diffuse.rays").string() + " --accel grid --stream");
    EXPECT_EQ(grid.status, 2) << grid.output;
    EXPECT_NE(grid.output.find("--stream: grid has no stream traversal"), std::string::npos) << grid.output;
}

/// A scene that moves: rays carry times (a version 2 file), every one in
/// the shutter, and trace answers at those times as brute force does; the
/// same rays without their times (at the opening) answer differently.
TEST(Cli, RaysAndTraceCarryTimesThroughAMovingScene) {
    const fs::path dir = temp_dir();
    const std::string scene = "gen:balls:2:motion";
    for (const char* kind : {"camera", "shadow", "diffuse"}) {
        const std::string rays = (dir / (std::string(kind) + ".rays")).string();
        const Result made = run("rays " + scene + " --kind " + kind + " --res 40 40 -o " + rays);
        ASSERT_EQ(made.status, 0) << made.output;
        EXPECT_NE(made.output.find("with times over the shutter"), std::string::npos) << made.output;
        const RayFile file = read_rays(rays);
        ASSERT_EQ(file.times.size(), file.rays.size());
        for (const float t : file.times) ASSERT_TRUE(t >= 0.0f && t <= 1.0f) << t;  // gen's shutter: 0 1
        std::vector<Hitf> answers[2];
        for (int k = 0; k < 2; ++k) {
            const std::string hits = (dir / (std::string(kind) + std::to_string(k) + ".hits")).string();
            const Result r = run("trace " + scene + " --rays " + rays + " -o " + hits + " --repeat 1" +
                                 (k == 0 ? "" : " --accel brute"));
            ASSERT_EQ(r.status, 0) << r.output;
            answers[k] = read_hits(hits);
        }
        ASSERT_EQ(answers[0].size(), answers[1].size());
        for (std::size_t i = 0; i < answers[0].size(); ++i) {
            ASSERT_EQ(answers[0][i].found(), answers[1][i].found()) << kind << " ray " << i;
            if (file.kind == RayKind::ClosestHit && answers[0][i].found()) {
                ASSERT_EQ(answers[0][i].t, answers[1][i].t) << kind << " ray " << i;
            }
        }
    }
    // The camera rays at the shutter's opening (a version 1 file) see the balls elsewhere.
    const RayFile timed = read_rays((dir / "camera.rays").string());
    write_rays((dir / "untimed.rays").string(), timed.kind, timed.rays);
    const std::string a = (dir / "a.hits").string(), b = (dir / "b.hits").string();
    ASSERT_EQ(run("trace " + scene + " --rays " + (dir / "camera.rays").string() + " -o " + a + " --repeat 1").status, 0);
    ASSERT_EQ(run("trace " + scene + " --rays " + (dir / "untimed.rays").string() + " -o " + b + " --repeat 1").status, 0);
    const auto ha = read_hits(a), hb = read_hits(b);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < ha.size(); ++i) differ += ha[i].t != hb[i].t;
    EXPECT_GT(differ, ha.size() / 20);
}

/// With no structure, builder or width named, trace runs the fastest measured
/// configuration for the kind of rays (app/default_config.cpp) and says so in --json; naming any of them turns that off.
TEST(Cli, TraceDefaultsToTheFastestConfigurationForTheRays) {
    const fs::path dir = temp_dir();
    const std::string scene = "gen:balls:2";
    struct Case {
        const char* kind;
        const char* workload;
        const char* accel;
        int packet;
    };
    // Without AVX-512: packets of 8, and diffuse rays one at a time through the BVH8.
    constexpr bool wide = kWidthCompiled<16>;
    for (const Case& c : {Case{"camera", "camera", "bvh4", wide ? 16 : 8}, Case{"shadow", "shadow", "bvh8", wide ? 16 : 8},
                          Case{"diffuse", "diffuse", wide ? "bvh4" : "bvh8", wide ? 16 : 1}}) {
        const std::string rays = (dir / (std::string("default_") + c.kind + ".rays")).string();
        ASSERT_EQ(run("rays " + scene + " --kind " + c.kind + " --res 32 32 -o " + rays).status, 0);
        const Result r = run("trace " + scene + " --rays " + rays + " --repeat 1 --json");
        ASSERT_EQ(r.status, 0) << r.output;
        const auto j = nlohmann::json::parse(r.output);
        EXPECT_TRUE(j["default_config"].get<bool>()) << c.kind;
        EXPECT_EQ(j["workload"], c.workload);
        EXPECT_EQ(j["accel"], c.accel) << c.kind;
        EXPECT_EQ(j["packet"].get<int>(), c.packet) << c.kind;
        // With AVX-512, diffuse rays go as streams.
        EXPECT_EQ(j["stream"].get<bool>(), wide && std::string(c.kind) == "diffuse") << c.kind;
        // Packets walk in groups of 128 rays (accel/bvh/wide_packet.h); single rays alone.
        EXPECT_EQ(j["group"].get<int>(), c.packet > 1 ? 128 / c.packet : 1) << c.kind;
        const Result named = run("trace " + scene + " --rays " + rays + " --repeat 1 --json --accel bvh2");
        ASSERT_EQ(named.status, 0) << named.output;
        const auto jn = nlohmann::json::parse(named.output);
        EXPECT_FALSE(jn["default_config"].get<bool>());
        EXPECT_EQ(jn["accel"], "bvh2");
        EXPECT_EQ(jn["packet"].get<int>(), 1);
        EXPECT_EQ(jn["group"].get<int>(), 1);
    }
    // --group names the group size and keeps the default structure; it is
    // refused for a structure that has no groups.
    const std::string rays = (dir / "default_camera.rays").string();
    const Result g = run("trace " + scene + " --rays " + rays + " --repeat 1 --json --group 2");
    ASSERT_EQ(g.status, 0) << g.output;
    const auto jg = nlohmann::json::parse(g.output);
    EXPECT_TRUE(jg["default_config"].get<bool>());
    EXPECT_EQ(jg["group"].get<int>(), 2);
    EXPECT_EQ(run("trace " + scene + " --rays " + rays + " --group 2 --accel grid --packet 8").status, 2);
    // The k-d tree and the octree group a fixed number of packets; --group 1
    // makes each walk alone, with the same hits.
    for (const auto& [kind, group] : {std::pair{"kdtree", 16}, std::pair{"octree", 8}}) {
        const std::string base = "trace " + scene + " --rays " + rays + " --repeat 1 --json --packet 8 --accel " + kind;
        const Result grouped = run(base), alone = run(base + " --group 1");
        ASSERT_EQ(grouped.status, 0) << grouped.output;
        ASSERT_EQ(alone.status, 0) << alone.output;
        const auto jgr = nlohmann::json::parse(grouped.output), jal = nlohmann::json::parse(alone.output);
        EXPECT_EQ(jgr["group"].get<int>(), group) << kind;
        EXPECT_EQ(jal["group"].get<int>(), 1) << kind;
        EXPECT_EQ(jgr["hits"], jal["hits"]) << kind;
        EXPECT_EQ(run(base + " --group 2").status, 2) << kind;
    }
    EXPECT_EQ(run("trace " + scene + " --rays " + rays + " --group 17").status, 2);
}

TEST(Cli, BadFlagsAreUsageErrors) {
    struct Case {
        std::string args, phrase;
    };
    const Case cases[] = {
        {"render " + scene_path("tetra.nff") + " --bogus", "unknown option '--bogus'"},
        {"render " + scene_path("tetra.nff") + " --res 0 10", "--res must be between 1 and 65536"},
        {"render " + scene_path("tetra.nff") + " --res 64", "--res needs 2 value(s)"},
        {"render " + scene_path("tetra.nff") + " --depth x", "--depth expects an integer"},
        {"render " + scene_path("tetra.nff") + " --tile 0", "--tile must be between 1 and 4096"},
        {"render " + scene_path("tetra.nff") + " --accel octopus", "unknown structure 'octopus'"},
        {"trace " + scene_path("tetra.nff"), "missing --rays"},
        {"render " + scene_path("tetra.nff") + " --packet 3", "--packet: expected 1, 4, 8 or 16"},
        {"render " + scene_path("tetra.nff") + " --accel brute --packet 8", "--packet 8: not available for brute"},
        {"render " + scene_path("tetra.nff") + " --sphere exact", "--sphere: expected geometric|algebraic|precise"},
        {"render " + scene_path("tetra.nff") + " --slabs fast", "--slabs: expected robust|plain, got 'fast'"},
        {"trace " + scene_path("tetra.nff") + " --rays x.rays --precision half", "--precision: expected float|double"},
        {"bench " + scene_path("tetra.nff") + " --rcp newton", "--rcp: expected exact|approx, got 'newton'"},
        {"render " + scene_path("tetra.nff") + " --accel embree --slabs plain", "--slabs does not apply to --accel embree"},
        {"render " + scene_path("tetra.nff") + " --embree-quality high",
         "--embree-quality applies to --accel embree and embree-robust only"},
        {"bench " + scene_path("tetra.nff") + " --accel embree-robust --embree-quality ultra",
         "--embree-quality: expected low|medium|high, got 'ultra'"},
        {"bench --tradeoff --precision double", "--precision does not apply to --tradeoff"},
        {"render " + scene_path("tetra.nff") + " --integrator photon", "--integrator: expected whitted, distribution or path"},
        {"render " + scene_path("tetra.nff") + " --spp 4", "--spp needs --integrator distribution or path"},
        {"render " + scene_path("tetra.nff") + " --integrator distribution --rr-depth 2", "--rr-depth needs --integrator path"},
        {"render " + scene_path("tetra.nff") + " --integrator path --sampler halton", "--sampler: expected regular|random|stratified|sobol"},
        {"render " + scene_path("tetra.nff") + " --integrator path --filter mitchell", "--filter: expected box|tent|gaussian"},
        {"render " + scene_path("tetra.nff") + " --integrator distribution --spp 0", "--spp must be between 1 and"},
        {"render " + scene_path("tetra.nff") + " --exposure nan", "--exposure expects a finite number"},
        {"render " + scene_path("tetra.nff") + " --save-rays ''", "--save-rays: expected a file prefix"},
        {"gen nosuch -o x.nff", "unknown generator 'nosuch'"},
        {"gen balls --size 99 -o x.nff", "--size must be between 1 and"},
        {"frobnicate", "unknown command 'frobnicate'"},
    };
    for (const Case& c : cases) {
        const Result r = run(c.args);
        EXPECT_EQ(r.status, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.phrase), std::string::npos) << c.args << "\n" << r.output;
    }
}

TEST(Cli, BadInputNamesTheFileAndLeavesOutputsAlone) {
    const fs::path dir = temp_dir();
    const fs::path bad = dir / "bad.nff";
    { std::ofstream(bad) << "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 8 8\ns 0 0 nan 1\n"; }
    const fs::path out = dir / "keep.png";
    { std::ofstream(out) << "previous image"; }
    const Result r = run("render " + bad.string() + " -o " + out.string());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.output.find(bad.string() + ":8:"), std::string::npos) << r.output;
    EXPECT_EQ(slurp(out), "previous image");

    const Result missing = run("info " + (dir / "no_such_scene.nff").string());
    EXPECT_EQ(missing.status, 1);
    EXPECT_NE(missing.output.find("no_such_scene.nff"), std::string::npos) << missing.output;

    const fs::path junk = dir / "junk.rays";
    { std::ofstream(junk) << "not rays at all"; }
    const Result rays = run("trace gen:tetra:1 --rays " + junk.string());
    EXPECT_EQ(rays.status, 1);
    EXPECT_NE(rays.output.find("junk.rays"), std::string::npos) << rays.output;

    // A scene at the edge of the float range: its shadow rays overflow, and
    // `rays` says so instead of writing a file no reader takes.
    const fs::path huge = dir / "huge.nff";
    { std::ofstream(huge) << "v from 0 -6 2 at 0 0 0 up 0 0 1 angle 40 hither 0.01 resolution 8 8\nl 4 -4 6\n"
                             "s 0 0 0 3e38\n"; }
    const fs::path set = dir / "set.rays";
    { std::ofstream(set) << "previous rays"; }
    const Result overflow = run("rays " + huge.string() + " --kind shadow -o " + set.string());
    EXPECT_EQ(overflow.status, 1) << overflow.output;
    EXPECT_NE(overflow.output.find("is not finite"), std::string::npos) << overflow.output;
    EXPECT_EQ(slurp(set), "previous rays");
}

}  // namespace
}  // namespace raypack
