// Scene-level cases: whole-scene tracing through the scalar reference BVH2.
#include <benchmark/benchmark.h>

#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "render/ray_sets.h"
#include "scene/load.h"

namespace raypack {
namespace {

/// Camera rays of a generated SPD scene through the scalar BVH2, one thread,
/// checked against the brute-force oracle on a sample before timing.
void scene_bench(benchmark::State& state, const char* spec) {
    const Scene scene = load_scene(spec);
    const auto bvh = build_accel(scene, AccelConfig{});
    const std::vector<Rayf> rays = camera_ray_set(scene, 256, 256);
    std::vector<Hitf> hits(rays.size());
    bvh->intersect(rays, hits);
    const BruteForce oracle(scene, KernelChoice{});
    for (std::size_t i = 0; i < rays.size(); i += 997) {
        const Hitf want = oracle.intersect1(rays[i]);
        if (want.found() != hits[i].found() || (want.found() && want.t != hits[i].t))
            return state.SkipWithError("validation: BVH2 disagrees with the brute-force oracle");
    }
    for (auto _ : state) bvh->intersect(rays, hits);
    state.counters["rays_per_second"] =
        benchmark::Counter(double(state.iterations()) * double(rays.size()), benchmark::Counter::kIsRate);
    state.counters["build_ms"] = bvh->stats().build_ms;
}

BENCHMARK_CAPTURE(scene_bench, balls, "gen:balls:4")->Name("scene/balls/bvh2/camera/1")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(scene_bench, tetra, "gen:tetra:6")->Name("scene/tetra/bvh2/camera/1")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(scene_bench, mount, "gen:mount:6")->Name("scene/mount/bvh2/camera/1")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace raypack

BENCHMARK_MAIN();
