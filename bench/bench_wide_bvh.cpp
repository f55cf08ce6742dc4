// Scene-level cases for the wide BVHs beside Embree (the BVH2's are in
// bench_scenes.cpp): scene/SCENE/ACCEL/KIND/1 traces the camera rays (closest hit) or the shadow
// rays (any hit) of a shared scene at 512 x 512, one thread, one ray at a
// time. Every case is checked against the brute-force oracle on a sample of
// its rays before it is timed.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "render/ray_sets.h"
#include "scene/load.h"

namespace raypack {
namespace {

constexpr int kResolution = 512;

/// A scene and its two ray sets, loaded once for all cases of that scene.
struct SceneRays {
    Scene scene;
    std::vector<Rayf> camera, shadow;
};

class LazyScene {
public:
    explicit LazyScene(std::string file) : file_(std::move(file)) {}
    const SceneRays& get() {
        if (!data_) {
            data_ = std::make_unique<SceneRays>();
            data_->scene = load_scene(std::string(RAYPACK_SCENE_DIR) + "/" + file_);
            data_->camera = camera_ray_set(data_->scene, kResolution, kResolution);
            data_->shadow = shadow_ray_set(data_->scene, kResolution, kResolution);
        }
        return *data_;
    }

private:
    std::string file_;
    std::unique_ptr<SceneRays> data_;
};

/// Every 61st ray against the oracle: the same hit or miss, the same t for
/// the same primitive (the structures run the oracle's kernels), another
/// primitive only at a t within 1e-5 (Embree: 1e-4, its own kernels).
bool validated(benchmark::State& state, const Accel& accel, const Scene& scene, const std::vector<Rayf>& rays,
               bool shadow) {
    const BruteForce oracle(scene, KernelChoice{});
    const bool own_kernels = accel.stats().name != "embree";
    std::size_t bad = 0, checked = 0;
    for (std::size_t i = 0; i < rays.size(); i += 61, ++checked) {
        if (shadow) {
            bad += accel.occluded1(rays[i]) != oracle.occluded1(rays[i]);
            continue;
        }
        const Hitf want = oracle.intersect1(rays[i]), got = accel.intersect1(rays[i]);
        if (want.found() != got.found()) {
            ++bad;
        } else if (want.found()) {
            const float rel = own_kernels ? 1e-5f : 1e-4f;
            const bool same = own_kernels && want.prim == got.prim
                                  ? want.t == got.t
                                  : std::fabs(want.t - got.t) <= rel * std::fabs(want.t);
            bad += !same;
        }
    }
    // Embree's kernels may disagree on a ray that grazes an edge or a silhouette.
    if (bad > (own_kernels ? 0 : checked / 1000)) {
        state.SkipWithError(("validation: " + std::to_string(bad) + " of " + std::to_string(checked) +
                             " sampled rays disagree with the brute-force oracle")
                                .c_str());
        return false;
    }
    return true;
}

void trace_scene(benchmark::State& state, std::shared_ptr<LazyScene> lazy, std::string kind, bool shadow) {
    const SceneRays& data = lazy->get();
    const std::vector<Rayf>& rays = shadow ? data.shadow : data.camera;
    if (rays.empty()) return state.SkipWithError("the scene has no light for shadow rays");
    AccelConfig config;
    config.kind = kind;
    const std::unique_ptr<Accel> accel = build_accel(data.scene, config);
    if (!validated(state, *accel, data.scene, rays, shadow)) return;
    std::vector<Hitf> hits(rays.size());
    std::vector<std::uint8_t> occluded(rays.size());
    for (auto _ : state) {
        if (shadow) {
            accel->occluded(rays, occluded);
            benchmark::DoNotOptimize(occluded.data());
        } else {
            accel->intersect(rays, hits);
            benchmark::DoNotOptimize(hits.data());
        }
    }
    state.counters["rays_per_second"] =
        benchmark::Counter(double(state.iterations()) * double(rays.size()), benchmark::Counter::kIsRate);
    state.counters["build_ms"] = accel->stats().build_ms;
}

/// Registers scene/SCENE/ACCEL/{camera,shadow}/1 for the shared scenes.
/// (A static initialiser, as the BENCHMARK macros are.)
int register_cases() {
    std::vector<std::string> kinds = {"bvh4", "bvh8"};
#ifdef RAYPACK_HAVE_EMBREE
    kinds.push_back("embree");
#endif
    for (const char* name : {"balls", "mount", "tetra", "teapot", "bunny"}) {
        const std::string file = std::string(name) + (std::string(name) == "bunny" ? ".obj" : ".nff");
        auto lazy = std::make_shared<LazyScene>(file);
        for (const std::string& kind : kinds) {
            for (const bool shadow : {false, true}) {
                const std::string id = std::string("scene/") + name + "/" + kind + "/" + (shadow ? "shadow" : "camera") + "/1";
                benchmark::RegisterBenchmark(id.c_str(), trace_scene, lazy, kind, shadow)
                    ->Unit(benchmark::kMillisecond);
            }
        }
    }
    return 0;
}

const int kRegistered = register_cases();

}  // namespace
}  // namespace raypack
