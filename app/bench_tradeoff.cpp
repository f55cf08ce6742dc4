#include "app/bench_tradeoff.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <cstdio>

#include "app/accel_options.h"
#include "app/bench_measure.h"
#include "app/bench_tradeoff_report.h"
#include "render/camera_rays.h"
#include "render/ray_sets.h"
#include "render/surface.h"
#include "scene/load.h"

namespace raypack::app {
namespace {

/// Input sizes: the full run meets the figures (>= 10 million leak
/// rays per triangle variant); --quick covers every family in seconds.
struct TradeoffSizes {
    std::uint64_t leak_rays, ulp_rays;
    int mesh_detail, tetra_size;
    int timing_res, self_res, image_res;
};

TradeoffSizes sizes_for(bool quick) {
    if (quick) return {1'000'000, 200'000, 0, 3, 128, 96, 64};
    return {10'000'000, 2'000'000, 1, 4, 512, 384, 192};
}

// The standard scenes: throughput and image error of triangle variants on
// the SPD teapot (triangles only, a reflective floor), of sphere and offset
// variants on SPD balls (spheres on a polygon floor, mirror-like balls).
constexpr const char* kTriangleScene = "gen:teapot:6";
constexpr const char* kSphereTimingScene = "gen:balls:3";
constexpr const char* kSphereImageScene = "gen:balls:2";

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n == 0 ? 0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Median, slowest and fastest pass in Mrays/s.
void set_throughput(TradeoffRow& row, std::size_t rays, const std::vector<double>& ms) {
    const double krays = double(rays) / 1e3;
    row.timed_rays = rays;
    row.repeat = int(ms.size());
    row.mrays_per_s_median = krays / std::max(1e-9, median(ms));
    row.mrays_per_s_min = krays / std::max(1e-9, *std::max_element(ms.begin(), ms.end()));
    row.mrays_per_s_max = krays / std::max(1e-9, *std::min_element(ms.begin(), ms.end()));
}

/// Milliseconds of `repeat` passes of each variant, taken in turns (pass 1
/// of every variant, then pass 2, ...) after one warm-up pass each, so that
/// the load of a shared machine falls on all variants alike and their
/// ratios hold within one run. One thread: figures per core.
std::vector<std::vector<double>> interleaved_passes(const std::vector<std::function<double()>>& variants, int repeat) {
    const ThreadLimit one_thread(1);
    std::vector<std::vector<double>> ms(variants.size());
    for (int pass = -1; pass < repeat; ++pass)
        for (std::size_t v = 0; v < variants.size(); ++v) {
            const double t = variants[v]();
            if (pass >= 0) ms[v].push_back(t);
        }
    return ms;
}

/// One pass over `set` (closest hit), in milliseconds.
double time_one_pass(const Accel& accel, const BenchRays& set) {
    std::size_t hits = 0;
    return time_passes(accel, 1, set, 1, hits).back();
}

class Stages {
public:
    void note(const std::string& what) const {
        std::fprintf(stderr, "[tradeoff] %s, %.1f s elapsed\n", what.c_str(), elapsed());
    }
    double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

private:
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// The scenes t errors are measured on: the mixed scene at sizes 1e-3 to
/// 1e3, and at size 1 moved 1e4 from the origin.
std::vector<ObjectScene> ulp_scenes() {
    std::vector<ObjectScene> scenes;
    for (float scale : {1e-3f, 1.0f, 1e3f}) scenes.push_back(mixed_convex_scene(scale, Vec3f{}));
    scenes.push_back(mixed_convex_scene(1, Vec3f{1e4f, 1e4f, 1e4f}));
    scenes.push_back(leak_test_spheres());
    return scenes;
}

/// t errors over every scene, the rays shared out evenly.
UlpError pooled_ulps(const std::vector<ObjectScene>& scenes, PrimKind kind, KernelChoice kernels, std::uint64_t rays) {
    // Pool by rerunning with every scene's primitives counted once: the
    // percentiles need all errors together, so merge the scenes first.
    Scene pooled;
    pooled.materials.push_back(Material{});
    for (const ObjectScene& o : scenes)
        for (std::uint32_t p = 0; p < o.scene.primitive_count(); ++p) {
            const PrimRef ref = o.scene.prims[p];
            if (ref.kind != kind) continue;
            if (kind == PrimKind::Sphere)
                pooled.add_sphere(o.scene.spheres.center[ref.index], o.scene.spheres.radius[ref.index], 0);
            else if (kind == PrimKind::Triangle)
                pooled.add_triangle(o.scene.triangles.p0[ref.index], o.scene.triangles.p1[ref.index],
                                    o.scene.triangles.p2[ref.index], 0);
        }
    pooled.update_features();
    return t_error_ulps(pooled, kind, kernels, rays);
}

WhittedOptions image_options(int res, OffsetPolicy offset) {
    WhittedOptions o;
    o.width = o.height = res;
    o.offset = offset;
    return o;
}

/// A family of primitive tests: its variants, where each is timed and
/// rendered, and how its leaks are counted.
struct KernelFamily {
    const char* name;
    PrimKind kind;
    const char* timing_scene;
    const char* image_scene;
    std::vector<std::pair<const char*, KernelChoice>> variants;
    ObjectScene leak_scene;
    LeakCounts (*count_leaks)(const ObjectScene&, const Accel&, std::uint64_t, std::uint64_t);
};

void run_kernel_family(const KernelFamily& family, const TradeoffPlan& plan, const TradeoffSizes& sizes,
                       const Stages& stages, std::vector<TradeoffRow>& rows) {
    const std::string name = family.name;
    const Scene timing_scene = load_scene(family.timing_scene), image_scene = load_scene(family.image_scene);
    const BenchRays camera = make_bench_rays(timing_scene, "camera", sizes.timing_res, sizes.timing_res);
    const std::vector<ObjectScene> ulp = ulp_scenes();
    const WhittedOptions options = image_options(sizes.image_res, kDefaultOffset);
    stages.note(name + ": double reference render of " + family.image_scene);
    const Image reference = render_double_reference(image_scene, options);
    std::vector<std::unique_ptr<Accel>> accels;
    std::vector<std::function<double()>> passes;
    for (const auto& [variant, kernels] : family.variants) {
        accels.push_back(build_accel(timing_scene, accel_config("bvh2", kernels)));
        passes.push_back([&camera, &accel = *accels.back()] { return time_one_pass(accel, camera); });
    }
    stages.note(name + ": timing the variants in turns");
    const auto ms = interleaved_passes(passes, plan.repeat);
    for (std::size_t v = 0; v < family.variants.size(); ++v) {
        const auto& [variant, kernels] = family.variants[v];
        stages.note(name + " " + variant);
        AccelConfig config;
        config.kind = "bvh2", config.kernels = kernels;
        TradeoffRow row;
        row.family = name, row.variant = variant, row.throughput_scene = family.timing_scene;
        row.throughput_rays = "camera";
        set_throughput(row, camera.rays.size(), ms[v]);
        row.leaks = family.count_leaks(family.leak_scene, *build_accel(family.leak_scene.scene, config),
                                       sizes.leak_rays, 1);
        row.t_ulps = pooled_ulps(ulp, family.kind, kernels, sizes.ulp_rays);
        Image image;
        render_whitted(image_scene, *build_accel(image_scene, config), options, image);
        row.image = image_error(image, reference);
        row.image_scene = family.image_scene;
        row.image_width = row.image_height = sizes.image_res;
        rows.push_back(std::move(row));
    }
}

/// One timed pass of the offset's own work: from each camera hit, the
/// surface, the offset origin and the shadow ray, then the occlusion query.
double time_shadow_pass(const Scene& scene, const Accel& accel, const RayOffset& offset,
                        const std::vector<Rayf>& camera, const std::vector<Hitf>& hits, std::vector<Rayf>& shadow,
                        std::vector<std::uint8_t>& occluded) {
    const auto start = std::chrono::steady_clock::now();
    const Vec3f light = scene.lights.front().position;
    constexpr std::size_t kBatch = 4096;
    tbb::parallel_for(std::size_t(0), camera.size(), kBatch, [&](std::size_t b) {
        const std::size_t end = std::min(camera.size(), b + kBatch);
        for (std::size_t i = b; i < end; ++i) {
            const Surface s = surface_at(scene, camera[i], hits[i]);
            const Vec3f n = dot(s.geometric_normal, camera[i].dir) < 0 ? s.geometric_normal : -s.geometric_normal;
            Rayf& r = shadow[i];
            r.org = offset.offset(offset.hit_point(scene, camera[i], hits[i], s.point), n);
            r.dir = light - r.org;
            r.tnear = offset.tnear();
            r.tfar = 1.0f - 1e-6f;
        }
        accel.occluded({shadow.data() + b, end - b}, {occluded.data() + b, end - b});
    });
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void run_offset_family(const TradeoffPlan& plan, const TradeoffSizes& sizes, const Stages& stages,
                       std::vector<TradeoffRow>& rows) {
    const Scene timing_scene = load_scene(kSphereTimingScene), image_scene = load_scene(kSphereImageScene);
    const auto timing_accel = build_accel(timing_scene, AccelConfig{});
    // The camera hits, once: the offset is timed from there.
    std::vector<Rayf> camera;
    std::vector<Hitf> hits;
    {
        const std::vector<Rayf> all = camera_ray_set(timing_scene, sizes.timing_res, sizes.timing_res);
        std::vector<Hitf> all_hits(all.size());
        timing_accel->intersect(all, all_hits);
        for (std::size_t i = 0; i < all.size(); ++i)
            if (all_hits[i].found()) camera.push_back(all[i]), hits.push_back(all_hits[i]);
    }
    const auto& placements = self_intersection_placements();
    std::vector<ObjectScene> placed;
    std::vector<std::unique_ptr<Accel>> placed_accels;
    placed.reserve(placements.size());  // each structure keeps a pointer to its scene
    for (const Placement& p : placements) {
        placed.push_back(mixed_convex_scene(p.scale, Vec3f{p.translation, p.translation, p.translation}));
        placed_accels.push_back(build_accel(placed.back().scene, AccelConfig{}));
    }
    stages.note("offset: double reference render of " + std::string(kSphereImageScene) + " (robust offset)");
    const Image reference = render_double_reference(image_scene, image_options(sizes.image_res, OffsetPolicy::Robust));
    const OffsetPolicy policies[] = {OffsetPolicy::Epsilon, OffsetPolicy::Scaled, OffsetPolicy::Robust};
    std::vector<Rayf> shadow(camera.size());
    std::vector<std::uint8_t> occluded(camera.size());
    std::vector<RayOffset> offsets;
    for (OffsetPolicy policy : policies) offsets.emplace_back(policy, timing_scene);
    std::vector<std::function<double()>> passes;
    for (const RayOffset& offset : offsets)
        passes.push_back([&, &offset = offset] {
            return time_shadow_pass(timing_scene, *timing_accel, offset, camera, hits, shadow, occluded);
        });
    stages.note("offset: timing the policies in turns");
    const auto ms = interleaved_passes(passes, plan.repeat);
    for (std::size_t v = 0; v < std::size(policies); ++v) {
        const OffsetPolicy policy = policies[v];
        stages.note(std::string("offset ") + offset_policy_name(policy));
        TradeoffRow row;
        row.family = "offset", row.variant = offset_policy_name(policy);
        row.throughput_scene = kSphereTimingScene, row.throughput_rays = "shadow";
        set_throughput(row, camera.size(), ms[v]);
        for (std::size_t i = 0; i < placed.size(); ++i)
            row.self.push_back(count_self_intersections(placed[i], *placed_accels[i], policy, sizes.self_res,
                                                        sizes.self_res));
        Image image;
        render_whitted(image_scene, *build_accel(image_scene, AccelConfig{}), image_options(sizes.image_res, policy), image);
        row.image = image_error(image, reference);
        row.image_scene = kSphereImageScene;
        row.image_width = row.image_height = sizes.image_res;
        rows.push_back(std::move(row));
    }
}

}  // namespace

int run_tradeoff(const TradeoffPlan& plan) {
    const TradeoffSizes sizes = sizes_for(plan.quick);
    const Stages stages;
    std::vector<TradeoffRow> rows;
    run_kernel_family({.name = "triangle", .kind = PrimKind::Triangle, .timing_scene = kTriangleScene,
                       .image_scene = kTriangleScene,
                       .variants = {{"moeller", {.triangle = TriangleMethod::Moeller}},
                                    {"watertight", {.triangle = TriangleMethod::Watertight}},
                                    {"plane", {.triangle = TriangleMethod::Plane}}},
                       .leak_scene = leak_test_meshes(sizes.mesh_detail, sizes.tetra_size),
                       .count_leaks = count_mesh_leaks},
                      plan, sizes, stages, rows);
    run_kernel_family({.name = "sphere", .kind = PrimKind::Sphere, .timing_scene = kSphereTimingScene,
                       .image_scene = kSphereImageScene,
                       .variants = {{"algebraic", {.sphere = SphereMethod::Algebraic}},
                                    {"geometric", {.sphere = SphereMethod::Geometric}},
                                    {"precise", {.sphere = SphereMethod::Precise}}},
                       .leak_scene = leak_test_spheres(),
                       .count_leaks = count_sphere_leaks},
                      plan, sizes, stages, rows);
    run_offset_family(plan, sizes, stages, rows);
    print_tradeoff_table(stdout, rows);
    std::printf("not measured (no such variant on this branch): --slabs, --rcp, --precision, --builder\n");
    if (!plan.json.empty()) write_tradeoff_json(plan.json, rows);
    if (!plan.csv.empty()) write_tradeoff_csv(plan.csv, rows);
    std::fprintf(stderr, "raypack bench --tradeoff%s: %zu rows in %.1f s\n", plan.quick ? " --quick" : "", rows.size(),
                 stages.elapsed());
    return 0;
}

}  // namespace raypack::app
