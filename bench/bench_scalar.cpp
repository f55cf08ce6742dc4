// Scalar reference path: per-kernel test rates and whole-scene BVH2 tracing.
// Names follow KERNEL/VARIANT/K with K = 1 (the SIMD widths come with the
// packet kernels).
#include <benchmark/benchmark.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "kernels/aabb.h"
#include "kernels/cone.h"
#include "kernels/sphere.h"
#include "kernels/triangle.h"
#include "render/ray_sets.h"
#include "scene/load.h"

namespace raypack {
namespace {

constexpr int kRays = 4096;

/// Rays from around (0, 0, -3) toward the unit cube, about half of which hit
/// the shapes below.
std::vector<Rayf> test_rays() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<Rayf> rays(kRays);
    for (Rayf& r : rays) {
        r.org = {u(rng) * 0.1f, u(rng) * 0.1f, -3.0f};
        r.dir = Vec3f{u(rng) * 0.5f, u(rng) * 0.5f, 3.0f} - r.org;
        r.tnear = 0;
        r.tfar = 100;
    }
    return rays;
}

template <class Test>
void run_kernel(benchmark::State& state, Test test) {
    const std::vector<Rayf> rays = test_rays();
    int hits = 0;
    for (const Rayf& r : rays) hits += test(r);
    if (hits == 0 || hits == kRays) state.SkipWithError("validation: the kernel hits all or none of the rays");
    for (auto _ : state)
        for (const Rayf& r : rays) benchmark::DoNotOptimize(test(r));
    state.counters["tests_per_second"] =
        benchmark::Counter(double(state.iterations()) * kRays, benchmark::Counter::kIsRate);
}

void sphere_bench(benchmark::State& state, SphereMethod m) {
    run_kernel(state, [m](const Rayf& r) {
        float t;
        return intersect_sphere(m, r, Vec3f{0, 0, 0}, 0.35f, t);
    });
}
void triangle_bench(benchmark::State& state, TriangleMethod m) {
    run_kernel(state, [m](const Rayf& r) {
        float t, u, v;
        return intersect_triangle(m, r, Vec3f{-0.5f, -0.5f, 0}, Vec3f{0.5f, -0.5f, 0}, Vec3f{0, 0.5f, 0.1f}, t, u, v);
    });
}
void cone_bench(benchmark::State& state) {
    run_kernel(state, [](const Rayf& r) {
        float t, s;
        return intersect_cone(r, Vec3f{-0.5f, 0, 0}, 0.3f, Vec3f{0.5f, 0, 0}, 0.1f, t, s);
    });
}
void aabb_bench(benchmark::State& state) {
    Box3f box;
    box.extend(Vec3f{-0.15f, -0.15f, -0.3f});
    box.extend(Vec3f{0.15f, 0.15f, 0.3f});
    run_kernel(state, [&box](const Rayf& r) {
        float entry;
        return intersect_aabb(r.org, reciprocal(r.dir), box, r.tnear, r.tfar, entry);
    });
}

BENCHMARK_CAPTURE(sphere_bench, algebraic, SphereMethod::Algebraic)->Name("sphere/algebraic/1");
BENCHMARK_CAPTURE(sphere_bench, geometric, SphereMethod::Geometric)->Name("sphere/geometric/1");
BENCHMARK_CAPTURE(triangle_bench, moeller, TriangleMethod::Moeller)->Name("triangle/moeller/1");
BENCHMARK_CAPTURE(triangle_bench, plane, TriangleMethod::Plane)->Name("triangle/plane/1");
BENCHMARK(cone_bench)->Name("cone/nff/1");
BENCHMARK(aabb_bench)->Name("aabb/plain/1");

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
