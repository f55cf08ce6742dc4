// Scene-level cases, the Google Benchmark face of `raypack bench`: every
// shared scene x structure x native packet width x ray kind, named
// scene/SCENE/ACCEL/RAYS/K (e.g. scene/balls/bvh8/camera/8), one thread,
// each checked against the brute-force oracle on a sample before timing.
// ACCEL grid-lanes is the grid with every packet stepping its lanes' own
// DDAs (GridConfig::coherent_packets off), to compare with the coherent walk.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/grid/grid_accel.h"
#include "measure/ray_sets.h"
#include "scene/load.h"

namespace raypack {
namespace {

constexpr int kRes = 512;                 // ray sets of 512 x 512 pixels, as raypack bench and bench_wide_bvh.cpp
constexpr std::size_t kBatch = 256;       // rays per call, as raypack bench
constexpr std::size_t kSampleStride = 61; // every 61st ray is checked against the oracle

const char* const kScenes[] = {"balls.nff", "tetra.nff", "mount.nff", "teapot.nff", "bunny.obj"};
const char* const kRayKinds[] = {"camera", "shadow", "diffuse"};

/// Scenes and ray sets are loaded on first use, so a --benchmark_filter run
/// only pays for what it selects.
struct SceneData {
    Scene scene;
    std::map<std::string, std::vector<Rayf>> rays;
};

SceneData& scene_data(const std::string& file) {
    static std::map<std::string, std::unique_ptr<SceneData>> cache;
    auto& slot = cache[file];
    if (!slot) {
        slot = std::make_unique<SceneData>();
        slot->scene = load_scene(std::string(RAYPACK_SCENE_DIR) + "/" + file);
        slot->rays["camera"] = camera_ray_set(slot->scene, kRes, kRes);
        slot->rays["shadow"] = shadow_ray_set(slot->scene, kRes, kRes);
        slot->rays["diffuse"] = diffuse_ray_set(slot->scene, kRes, kRes, 1);
    }
    return *slot;
}

/// All rays in batches through the packet path; occlusion stored as prim 0.
void trace(const Accel& accel, int packet, bool any_hit, const std::vector<Rayf>& rays, std::vector<Hitf>& hits) {
    std::uint8_t occluded[kBatch];
    for (std::size_t lo = 0; lo < rays.size(); lo += kBatch) {
        const std::size_t n = std::min(kBatch, rays.size() - lo);
        const std::span<const Rayf> batch(rays.data() + lo, n);
        if (!any_hit) {
            accel.intersect_packets(packet, batch, std::span<Hitf>(hits.data() + lo, n));
            continue;
        }
        accel.occluded_packets(packet, batch, std::span<std::uint8_t>(occluded, n));
        for (std::size_t i = 0; i < n; ++i) hits[lo + i].prim = occluded[i] ? 0 : kNoPrim;
    }
}

/// Empty if the sample agrees with the oracle, else what differs.
std::string disagreement(const Scene& scene, bool any_hit, const std::vector<Rayf>& rays,
                         const std::vector<Hitf>& hits) {
    const auto oracle = build_accel(scene, accel_config("brute"));
    for (std::size_t i = 0; i < rays.size(); i += kSampleStride) {
        const Hitf want = oracle->intersect1(rays[i]);
        const bool found = any_hit ? oracle->occluded1(rays[i]) : want.found();
        const bool same = found == hits[i].found() &&
                          (any_hit || !found || std::fabs(want.t - hits[i].t) <= 1e-5f * std::fabs(want.t));
        if (!same) return "ray " + std::to_string(i) + " disagrees with the brute-force oracle";
    }
    return {};
}

/// The structure `kind` names, or the grid without coherent packets for "grid-lanes".
std::unique_ptr<Accel> build_structure(const Scene& scene, const std::string& kind) {
    if (kind != "grid-lanes") return build_accel(scene, accel_config(kind));
    GridConfig lanes;
    lanes.coherent_packets = false;
    return std::make_unique<GridAccel>(scene, accel_config("grid"), lanes);
}

void scene_case(benchmark::State& state, const std::string& file, const std::string& kind, const std::string& rays_kind,
                int packet) {
    SceneData& data = scene_data(file);
    const std::vector<Rayf>& rays = data.rays.at(rays_kind);
    if (rays.empty()) return state.SkipWithError("no rays of this kind in this scene");
    const bool any_hit = rays_kind == "shadow";
    // Timed here: "grid-lanes" is constructed directly, not by build_accel.
    const auto start = std::chrono::steady_clock::now();
    const auto accel = build_structure(data.scene, kind);
    const double build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::vector<Hitf> hits(rays.size());
    trace(*accel, packet, any_hit, rays, hits);
    if (const std::string why = disagreement(data.scene, any_hit, rays, hits); !why.empty())
        return state.SkipWithError(("validation: " + why).c_str());
    for (auto _ : state) trace(*accel, packet, any_hit, rays, hits);
    state.counters["rays_per_second"] =
        benchmark::Counter(double(state.iterations()) * double(rays.size()), benchmark::Counter::kIsRate);
    state.counters["build_ms"] = build_ms;
}

/// bench_wide_bvh.cpp has the single-ray camera and shadow cases of the
/// wide BVHs and Embree under the same names.
bool registered_in_bench_wide_bvh(const std::string& kind, const std::string& rays_kind, int packet) {
    return (kind == "bvh4" || kind == "bvh8" || is_embree_kind(kind)) && packet == 1 && rays_kind != "diffuse";
}

/// One case per native width of each structure (asked of a one-sphere scene).
void register_scene_cases() {
    const Scene probe = load_scene("gen:balls:1");
    std::vector<std::string> kinds(accel_kinds().begin(), accel_kinds().end());
    kinds.insert(std::find(kinds.begin(), kinds.end(), "grid") + 1, "grid-lanes");
    for (const std::string& kind : kinds) {
        if (kind == "brute") continue;  // the oracle: minutes per case on the large scenes
        const auto accel = build_structure(probe, kind);
        for (int packet : {1, 4, 8, 16}) {
            if (!accel->supports_packet(packet)) continue;
            for (const char* file : kScenes)
                for (const char* rays_kind : kRayKinds) {
                    if (registered_in_bench_wide_bvh(kind, rays_kind, packet)) continue;
                    const std::string scene = std::string(file).substr(0, std::string(file).find('.'));
                    const std::string name = "scene/" + scene + "/" + kind + "/" + rays_kind + "/" + std::to_string(packet);
                    benchmark::RegisterBenchmark(name.c_str(), scene_case, std::string(file), kind,
                                                 std::string(rays_kind), packet)
                        ->Unit(benchmark::kMillisecond);
                }
        }
    }
}

}  // namespace
}  // namespace raypack

int main(int argc, char** argv) {
    raypack::register_scene_cases();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
