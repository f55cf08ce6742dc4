#pragma once
// Shared pieces of the kernel microbenchmarks: seeded rays as SoA, packet
// loads for any width, validation against the width-1 path, and the
// tests_per_second counter. Names follow KERNEL/VARIANT/K; the 1xM shape
// (one ray against a block of M primitives or boxes) is KERNEL_1xM/VARIANT/M.
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "kernels/ray_packet.h"

namespace raypack::bench {

/// Rays as SoA, padded to a multiple of 16. They start around (0, 0, -3) and
/// aim at points of the square [-0.5, 0.5]^2 in the plane z = 0, so shapes of
/// size ~0.5 around the origin are hit by a fair share of them.
struct RaySoA {
    std::size_t n = 0;
    std::vector<float> ox, oy, oz, dx, dy, dz, rdx, rdy, rdz, tnear, tfar;
};

inline RaySoA make_rays(std::size_t n, unsigned seed = 7) {
    n = (n + 15) / 16 * 16;
    RaySoA r;
    r.n = n;
    for (auto* v : {&r.ox, &r.oy, &r.oz, &r.dx, &r.dy, &r.dz, &r.rdx, &r.rdy, &r.rdz, &r.tnear, &r.tfar}) v->resize(n);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3f o{u(rng) * 0.1f, u(rng) * 0.1f, -3.0f};
        const Vec3f d = Vec3f{u(rng) * 0.5f, u(rng) * 0.5f, 0.0f} - o;
        const Vec3f rd = reciprocal(d);
        r.ox[i] = o.x; r.oy[i] = o.y; r.oz[i] = o.z;
        r.dx[i] = d.x; r.dy[i] = d.y; r.dz[i] = d.z;
        r.rdx[i] = rd.x; r.rdy[i] = rd.y; r.rdz[i] = rd.z;
        r.tnear[i] = 0.0f;
        r.tfar[i] = 100.0f;
    }
    return r;
}

/// Rays i .. i+lanes-1 in lanes of F.
template <class F>
RAYPACK_INLINE RayLanes<F> load_rays(const RaySoA& r, std::size_t i) {
    RayLanes<F> p;
    p.org = {load_lanes<F>(&r.ox[i]), load_lanes<F>(&r.oy[i]), load_lanes<F>(&r.oz[i])};
    p.dir = {load_lanes<F>(&r.dx[i]), load_lanes<F>(&r.dy[i]), load_lanes<F>(&r.dz[i])};
    p.rdir = {load_lanes<F>(&r.rdx[i]), load_lanes<F>(&r.rdy[i]), load_lanes<F>(&r.rdz[i])};
    p.tnear = load_lanes<F>(&r.tnear[i]);
    p.tfar = load_lanes<F>(&r.tfar[i]);
    return p;
}

/// Ray i broadcast to every lane of F.
template <class F>
RAYPACK_INLINE RayLanes<F> broadcast_ray(const RaySoA& r, std::size_t i) {
    RayLanes<F> p;
    p.org = {F(r.ox[i]), F(r.oy[i]), F(r.oz[i])};
    p.dir = {F(r.dx[i]), F(r.dy[i]), F(r.dz[i])};
    p.rdir = {F(r.rdx[i]), F(r.rdy[i]), F(r.rdz[i])};
    p.tnear = F(r.tnear[i]);
    p.tfar = F(r.tfar[i]);
    return p;
}

/// Reports ray-primitive (or ray-box) tests per second.
inline void set_tests_per_second(benchmark::State& state, double tests_per_iteration) {
    state.counters["tests_per_second"] =
        benchmark::Counter(double(state.iterations()) * tests_per_iteration, benchmark::Counter::kIsRate);
}

/// Marks the benchmark failed (never timed) when a validation did not hold.
inline bool validated(benchmark::State& state, bool ok, const std::string& what) {
    if (!ok) state.SkipWithError(("validation failed: " + what).c_str());
    return ok;
}

}  // namespace raypack::bench
