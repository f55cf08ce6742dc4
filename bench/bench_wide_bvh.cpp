// Scene-level cases for the wide BVHs beside Embree (the BVH2's are in
// bench_scenes.cpp): scene/SCENE/ACCEL/KIND/K traces the camera rays
// (closest hit), the shadow rays (any hit) or the "diffuse" rays (closest
// hit: from each camera hit in a uniformly random direction, incoherent, a
// stand-in for diffuse bounces) of a shared scene at 512 x 512, one thread,
// in packets of K (1: one ray at a time). Every case is checked against the
// brute-force oracle on a sample of its rays before it is timed, and its
// packet answers against its single-ray ones on all rays.
// switch/SCENE/bvhN/KIND/K/S measures the packet traversal's fallback to
// single rays below S active lanes (accel/bvh/wide_packet.h).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/bvh/wide_bvh_accel.h"
#include "measure/ray_sets.h"
#include "scene/load.h"

namespace raypack {
namespace {

constexpr int kResolution = 512;

/// A scene and its two ray sets, loaded once for all cases of that scene.
struct SceneRays {
    Scene scene;
    std::vector<Rayf> camera, shadow, diffuse;
    const std::vector<Rayf>& of(const std::string& kind) const {
        return kind == "camera" ? camera : kind == "shadow" ? shadow : diffuse;
    }
};

/// One ray per camera hit, from the hit point in a uniformly random
/// direction (seeded), in pixel order: neighbours share an origin region
/// but not a direction, the case where packets lose (Benthin et al. 2012).
std::vector<Rayf> diffuse_ray_set(const Scene& scene, const std::vector<Rayf>& camera) {
    AccelConfig config;
    config.kind = "bvh8";
    const std::unique_ptr<Accel> accel = build_accel(scene, config);
    std::vector<Hitf> hits(camera.size());
    accel->intersect(camera, hits);
    std::mt19937 rng(2012);
    std::normal_distribution<float> g;
    std::vector<Rayf> rays;
    for (std::size_t i = 0; i < camera.size(); ++i) {
        if (!hits[i].found()) continue;
        Rayf r;
        r.org = camera[i].org + camera[i].dir * hits[i].t;
        do r.dir = {g(rng), g(rng), g(rng)};
        while (dot(r.dir, r.dir) < 1e-6f);
        r.dir = normalize(r.dir);
        r.tnear = 1e-3f;
        rays.push_back(r);
    }
    return rays;
}

class LazyScene {
public:
    explicit LazyScene(std::string file) : file_(std::move(file)) {}
    const SceneRays& get() {
        if (!data_) {
            data_ = std::make_unique<SceneRays>();
            data_->scene = load_scene(std::string(RAYPACK_SCENE_DIR) + "/" + file_);
            data_->camera = camera_ray_set(data_->scene, kResolution, kResolution);
            data_->shadow = shadow_ray_set(data_->scene, kResolution, kResolution);
            data_->diffuse = diffuse_ray_set(data_->scene, data_->camera);
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
    const bool own_kernels = !is_embree_kind(accel.stats().name);
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

/// Traces `rays` in packets of `width`.
void trace(const Accel& accel, int width, bool shadow, const std::vector<Rayf>& rays, std::vector<Hitf>& hits,
           std::vector<std::uint8_t>& occluded) {
    if (shadow) {
        accel.occluded_packets(width, rays, occluded);
        benchmark::DoNotOptimize(occluded.data());
    } else {
        accel.intersect_packets(width, rays, hits);
        benchmark::DoNotOptimize(hits.data());
    }
}

/// Packets against single rays on every ray: the same hit or miss (or
/// occlusion), t within 1e-5 (wide_packet_traversal.h; Embree: 1e-4).
bool packets_agree(benchmark::State& state, const Accel& accel, int width, bool shadow,
                   const std::vector<Rayf>& rays) {
    if (width == 1) return true;
    std::vector<Hitf> one(rays.size()), packet(rays.size());
    std::vector<std::uint8_t> occ_one(rays.size()), occ_packet(rays.size());
    trace(accel, 1, shadow, rays, one, occ_one);
    trace(accel, width, shadow, rays, packet, occ_packet);
    const float rel = is_embree_kind(accel.stats().name) ? 1e-4f : 1e-5f;
    std::size_t bad = 0;
    for (std::size_t i = 0; i < rays.size(); ++i)
        bad += shadow ? occ_one[i] != occ_packet[i]
                      : one[i].found() != packet[i].found() ||
                            std::fabs(one[i].t - packet[i].t) > rel * std::fabs(one[i].t);
    if (bad == 0) return true;
    state.SkipWithError(("validation: " + std::to_string(bad) + " of " + std::to_string(rays.size()) +
                         " packet answers differ from single rays")
                            .c_str());
    return false;
}

void time_trace(benchmark::State& state, const Accel& accel, int width, bool shadow, const std::vector<Rayf>& rays) {
    std::vector<Hitf> hits(rays.size());
    std::vector<std::uint8_t> occluded(rays.size());
    for (auto _ : state) trace(accel, width, shadow, rays, hits, occluded);
    state.counters["rays_per_second"] =
        benchmark::Counter(double(state.iterations()) * double(rays.size()), benchmark::Counter::kIsRate);
    // build_accel's time; none for a structure constructed here (switch/ cases).
    if (accel.stats().build_ms > 0) state.counters["build_ms"] = accel.stats().build_ms;
}

void trace_scene(benchmark::State& state, std::shared_ptr<LazyScene> lazy, std::string kind, std::string rays_kind,
                 int width) {
    const SceneRays& data = lazy->get();
    const bool shadow = rays_kind == "shadow";
    const std::vector<Rayf>& rays = data.of(rays_kind);
    if (rays.empty()) return state.SkipWithError("the scene has no light for shadow rays");
    AccelConfig config;
    config.kind = kind;
    const std::unique_ptr<Accel> accel = build_accel(data.scene, config);
    if (!accel->supports_packet(width)) return state.SkipWithError("packet width not compiled in");
    if (!validated(state, *accel, data.scene, rays, shadow) || !packets_agree(state, *accel, width, shadow, rays))
        return;
    time_trace(state, *accel, width, shadow, rays);
}

/// The packet traversal of an N-wide tree with packets of `width` that
/// fall back to single rays below `switch_below` active lanes.
template <int N>
void trace_switch(benchmark::State& state, std::shared_ptr<LazyScene> lazy, std::string rays_kind, int width,
                  int switch_below) {
    const SceneRays& data = lazy->get();
    WideBvhAccel<N, 8> accel(data.scene, AccelConfig{});
    if (!accel.supports_packet(width)) return state.SkipWithError("packet width not compiled in");
    accel.set_packet_config(width, WidePacketConfig{switch_below});
    const bool shadow = rays_kind == "shadow";
    if (!packets_agree(state, accel, width, shadow, data.of(rays_kind))) return;
    time_trace(state, accel, width, shadow, data.of(rays_kind));
}

/// Registers scene/SCENE/ACCEL/{camera,shadow,diffuse}/K for the shared
/// scenes and switch/... for two of them. (A static initialiser, as the
/// BENCHMARK macros are.)
int register_cases() {
    std::vector<std::string> kinds = {"bvh4", "bvh8"};
#ifdef RAYPACK_HAVE_EMBREE
    kinds.push_back("embree");
    kinds.push_back("embree-robust");
#endif
    for (const char* name : {"balls", "mount", "tetra", "teapot", "bunny"}) {
        const std::string file = std::string(name) + (std::string(name) == "bunny" ? ".obj" : ".nff");
        auto lazy = std::make_shared<LazyScene>(file);
        for (const std::string& kind : kinds)
            for (const char* rays : {"camera", "shadow", "diffuse"})
                for (const int width : {1, 4, 8, 16}) {
                    const std::string id = std::string("scene/") + name + "/" + kind + "/" + rays + "/" +
                                           std::to_string(width);
                    benchmark::RegisterBenchmark(id.c_str(), trace_scene, lazy, kind, std::string(rays), width)
                        ->Unit(benchmark::kMillisecond);
                }
        if (std::string(name) != "teapot" && std::string(name) != "mount") continue;
        for (const char* rays : {"camera", "diffuse"})
            for (const int width : {8, 16})
                for (const int below : {0, 2, 4, 6, 8, 12, 17}) {
                    if (below > width + 1) continue;
                    for (const int n : {4, 8}) {
                        const std::string id = std::string("switch/") + name + "/bvh" + std::to_string(n) + "/" +
                                               rays + "/" + std::to_string(width) + "/" + std::to_string(below);
                        benchmark::RegisterBenchmark(id.c_str(), n == 4 ? trace_switch<4> : trace_switch<8>, lazy,
                                                     std::string(rays), width, below)
                            ->Unit(benchmark::kMillisecond);
                    }
                }
    }
    return 0;
}

const int kRegistered = register_cases();

}  // namespace
}  // namespace raypack
