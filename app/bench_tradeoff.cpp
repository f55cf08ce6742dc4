#include "app/bench_tradeoff.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>

#include "accel/bvh/bvh_builders.h"
#include "accel/threads_spread.h"
#include "app/accel_options.h"
#include "app/bench_measure.h"
#include "app/bench_tradeoff_report.h"
#include "render/camera_rays.h"
#include "measure/ray_sets.h"
#include "measure/scale_invariance.h"
#include "render/surface.h"
#include "scene/load.h"

namespace raypack::app {
namespace {

/// Input sizes: the full run meets the figures (>= 10 million leak
/// rays per row at closed meshes); --quick covers every family in seconds.
struct TradeoffSizes {
    std::uint64_t leak_rays, ulp_rays;
    int mesh_detail, tetra_size;
    int timing_res, self_res, image_res;
};

TradeoffSizes sizes_for(bool quick) {
    if (quick) return {1'000'000, 200'000, 0, 3, 128, 96, 64};
    return {10'000'000, 2'000'000, 1, 4, 512, 384, 192};
}

// The standard scenes: throughput and image error of triangle, slab, rcp,
// precision and builder variants on the SPD teapot (triangles only, a
// reflective floor), of sphere and offset variants on SPD balls (spheres on
// a polygon floor, mirror-like balls).
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

/// One row of a kernel family: the structure, its builder and kernels.
struct TradeVariant {
    const char* name;
    AccelConfig config;
};

TradeVariant variant(const char* name, const char* structure, KernelChoice kernels, const char* builder = "binned") {
    AccelConfig config = accel_config(structure, kernels);
    config.builder = builder;
    return {name, config};
}

/// The double reference renders, each made once: they take longer than
/// everything else they are compared with, and several families share one.
class ReferenceImages {
public:
    const Image& get(const char* scene_name, const Scene& scene, const WhittedOptions& options, const Stages& stages) {
        const std::string key = std::string(scene_name) + " " + offset_policy_name(options.offset);
        auto it = images_.find(key);
        if (it == images_.end()) {
            stages.note("double reference render of " + key);
            it = images_.emplace(key, render_double_reference(scene, options)).first;
        }
        return it->second;
    }

private:
    std::map<std::string, Image> images_;
};

/// The error measures of one configuration, kept so that a configuration
/// that recurs in another family (precision float is triangle moeller, rcp
/// exact and builder binned are slabs robust) is measured once: every
/// measure is deterministic, so a second run would only repeat the figures.
struct Measured {
    LeakCounts leaks;
    std::optional<UlpError> t_ulps;
    ImageError image;
};

/// A family of kernel or structure variants: its variants, where each is
/// timed and rendered, and how its leaks are counted.
struct KernelFamily {
    const char* name;
    PrimKind kind;
    const char* timing_scene;
    const char* image_scene;
    std::vector<TradeVariant> variants;
    const ObjectScene* leak_scene;
    LeakCounts (*count_leaks)(const ObjectScene&, const Accel&, std::uint64_t, std::uint64_t);
    /// False where the variants cannot change t (slab tests, reciprocals,
    /// builders only decide which primitives get tested): the column would
    /// repeat the primitive test's figure, which its own family reports.
    bool measure_t = true;
    /// Time the builds of the timing scene and report the SAH cost.
    bool builds = false;
};

using MeasuredCache = std::map<std::string, Measured>;

void run_kernel_family(const KernelFamily& family, const TradeoffPlan& plan, const TradeoffSizes& sizes,
                       const Stages& stages, ReferenceImages& references, MeasuredCache& measured,
                       std::vector<TradeoffRow>& rows) {
    const std::string name = family.name;
    const Scene timing_scene = load_scene(family.timing_scene), image_scene = load_scene(family.image_scene);
    const BenchRays camera = make_bench_rays(timing_scene, "camera", sizes.timing_res, sizes.timing_res);
    const std::vector<ObjectScene> ulp = family.measure_t ? ulp_scenes() : std::vector<ObjectScene>{};
    const WhittedOptions options = image_options(sizes.image_res, kDefaultOffset);
    const Image& reference = references.get(family.image_scene, image_scene, options, stages);
    std::vector<std::unique_ptr<Accel>> accels;
    std::vector<std::function<double()>> passes, builds;
    for (const TradeVariant& v : family.variants) {
        accels.push_back(build_accel(timing_scene, v.config));
        passes.push_back([&camera, &accel = *accels.back()] { return time_one_pass(accel, camera); });
        builds.push_back([&timing_scene, &config = v.config] { return build_accel(timing_scene, config)->stats().build_ms; });
    }
    stages.note(name + ": timing the variants in turns");
    const auto ms = interleaved_passes(passes, plan.repeat);
    std::vector<std::vector<double>> build_ms;
    if (family.builds) {
        stages.note(name + ": timing the builds in turns");
        build_ms = interleaved_passes(builds, plan.repeat);
    }
    for (std::size_t i = 0; i < family.variants.size(); ++i) {
        const TradeVariant& v = family.variants[i];
        TradeoffRow row;
        row.family = name, row.variant = v.name, row.throughput_scene = family.timing_scene;
        row.throughput_rays = "camera";
        set_throughput(row, camera.rays.size(), ms[i]);
        // Everything the measures depend on besides the fixed sizes and seeds.
        char leak_scene[32];
        std::snprintf(leak_scene, sizeof leak_scene, "%p", static_cast<const void*>(family.leak_scene));
        const std::string key = v.config.kind + " " + v.config.builder + " " + kernel_choice_summary(v.config.kernels) +
                                " " + family.image_scene + " " + leak_scene + (family.measure_t ? " t" : "");
        auto known = measured.find(key);
        if (known == measured.end()) {
            stages.note(name + " " + v.name + " (" + v.config.kind + ")");
            Measured m;
            m.leaks = family.count_leaks(*family.leak_scene, *build_accel(family.leak_scene->scene, v.config),
                                         sizes.leak_rays, 1);
            if (family.measure_t) m.t_ulps = pooled_ulps(ulp, family.kind, v.config.kernels, sizes.ulp_rays);
            Image image;
            render_whitted(image_scene, *build_accel(image_scene, v.config), options, image);
            m.image = image_error(image, reference);
            known = measured.emplace(key, m).first;
        } else {
            stages.note(name + " " + v.name + " (" + v.config.kind + "): errors as measured above, same configuration");
        }
        row.leaks = known->second.leaks;
        row.t_ulps = known->second.t_ulps;
        row.image = known->second.image;
        row.image_scene = family.image_scene;
        row.image_width = row.image_height = sizes.image_res;
        row.structure = v.config.kind, row.builder = v.config.builder;
        row.kernels = kernel_choice_summary(v.config.kernels);
        if (family.builds) {
            row.build_ms = median(build_ms[i]);
            row.sah_cost = accels[i]->stats().sah_cost;
        }
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
    ThreadsSpread spread;  // one CPU per thread, as the other timed passes
    tbb::parallel_for(std::size_t(0), camera.size(), kBatch, [&](std::size_t b) {
        spread.enter();
        const std::size_t end = std::min(camera.size(), b + kBatch);
        for (std::size_t i = b; i < end; ++i) {
            const Surface s = surface_at(scene, camera[i], hits[i]);
            const Vec3f n = dot(s.geometric_normal, camera[i].dir) < 0 ? s.geometric_normal : -s.geometric_normal;
            spawn_ray_to(offset.offset(offset.hit_point(scene, camera[i], hits[i], s.point), n), light, offset, shadow[i]);
        }
        accel.occluded({shadow.data() + b, end - b}, {occluded.data() + b, end - b});
    });
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void run_offset_family(const TradeoffPlan& plan, const TradeoffSizes& sizes, const Stages& stages,
                       ReferenceImages& references, std::vector<TradeoffRow>& rows) {
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
    const Image& reference =
        references.get(kSphereImageScene, image_scene, image_options(sizes.image_res, OffsetPolicy::Robust), stages);
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
        for (const Placement& p : placements)
            row.placed_image.push_back(scale_invariance_error(image_scene, policy, p.scale,
                                                              Vec3f{p.translation, p.translation, p.translation},
                                                              sizes.image_res, sizes.image_res));
        Image image;
        render_whitted(image_scene, *build_accel(image_scene, AccelConfig{}), image_options(sizes.image_res, policy), image);
        row.image = image_error(image, reference);
        row.image_scene = kSphereImageScene;
        row.image_width = row.image_height = sizes.image_res;
        row.structure = "bvh2", row.builder = AccelConfig{}.builder;
        row.kernels = kernel_choice_summary(KernelChoice{});
        rows.push_back(std::move(row));
    }
}

}  // namespace

int run_tradeoff(const TradeoffPlan& plan) {
    const TradeoffSizes sizes = sizes_for(plan.quick);
    const Stages stages;
    std::vector<TradeoffRow> rows;
    ReferenceImages references;
    MeasuredCache measured;
    const ObjectScene meshes = leak_test_meshes(sizes.mesh_detail, sizes.tetra_size);
    const ObjectScene spheres = leak_test_spheres();
    const KernelChoice moeller{.triangle = TriangleMethod::Moeller}, watertight{.triangle = TriangleMethod::Watertight};
    run_kernel_family({.name = "triangle", .kind = PrimKind::Triangle, .timing_scene = kTriangleScene,
                       .image_scene = kTriangleScene,
                       .variants = {variant("moeller", "bvh2", moeller), variant("watertight", "bvh2", watertight),
                                    variant("plane", "bvh2", {.triangle = TriangleMethod::Plane})},
                       .leak_scene = &meshes, .count_leaks = count_mesh_leaks},
                      plan, sizes, stages, references, measured, rows);
    run_kernel_family({.name = "sphere", .kind = PrimKind::Sphere, .timing_scene = kSphereTimingScene,
                       .image_scene = kSphereImageScene,
                       .variants = {variant("algebraic", "bvh2", {.sphere = SphereMethod::Algebraic}),
                                    variant("geometric", "bvh2", {.sphere = SphereMethod::Geometric}),
                                    variant("precise", "bvh2", {.sphere = SphereMethod::Precise})},
                       .leak_scene = &spheres, .count_leaks = count_sphere_leaks},
                      plan, sizes, stages, references, measured, rows);
    // Slabs and reciprocals with watertight triangles, so that a leak is the
    // traversal's; through BVH2 and through BVH8, whose ordered node test
    // computes its slabs apart from the BVH2's.
    KernelChoice plain = watertight, approx = watertight;
    plain.slabs = SlabMethod::Plain;
    approx.rcp = RcpMethod::Approx;
    std::vector<TradeVariant> slabs, rcp;
    for (const char* structure : {"bvh2", "bvh8"}) {
        slabs.push_back(variant("plain", structure, plain));
        slabs.push_back(variant("robust", structure, watertight));
        rcp.push_back(variant("exact", structure, watertight));
        rcp.push_back(variant("approx", structure, approx));
    }
    run_kernel_family({.name = "slabs", .kind = PrimKind::Triangle, .timing_scene = kTriangleScene,
                       .image_scene = kTriangleScene, .variants = slabs, .leak_scene = &meshes,
                       .count_leaks = count_mesh_leaks, .measure_t = false},
                      plan, sizes, stages, references, measured, rows);
    run_kernel_family({.name = "rcp", .kind = PrimKind::Triangle, .timing_scene = kTriangleScene,
                       .image_scene = kTriangleScene, .variants = rcp, .leak_scene = &meshes,
                       .count_leaks = count_mesh_leaks, .measure_t = false},
                      plan, sizes, stages, references, measured, rows);
    // Default kernels: the price and the gain of double on the default test.
    KernelChoice in_double = moeller;
    in_double.precision = Precision::Double;
    run_kernel_family({.name = "precision", .kind = PrimKind::Triangle, .timing_scene = kTriangleScene,
                       .image_scene = kTriangleScene,
                       .variants = {variant("float", "bvh2", moeller), variant("double", "bvh2", in_double)},
                       .leak_scene = &meshes, .count_leaks = count_mesh_leaks},
                      plan, sizes, stages, references, measured, rows);
    // Watertight triangles: Moeller's own leaks would hide a builder's (SBVH
    // clips triangles to split boxes; a box clipped too tight leaks).
    std::vector<TradeVariant> builders;
    for (const char* builder : bvh_builder_names()) builders.push_back(variant(builder, "bvh2", watertight, builder));
    run_kernel_family({.name = "builder", .kind = PrimKind::Triangle, .timing_scene = kTriangleScene,
                       .image_scene = kTriangleScene, .variants = builders, .leak_scene = &meshes,
                       .count_leaks = count_mesh_leaks, .measure_t = false, .builds = true},
                      plan, sizes, stages, references, measured, rows);
    run_offset_family(plan, sizes, stages, references, rows);
    print_tradeoff_table(stdout, rows);
    std::printf("\nslabs, rcp, builder: watertight triangles, so that a leak is the traversal's or the builder's;\n"
                "no t error (they leave the primitive test, hence t, unchanged). builder: build ms is the median of\n"
                "%d one-thread builds of %s, SAH cost of its BVH2. Kernels and structure of each row: --json/--csv.\n",
                plan.repeat, kTriangleScene);
    if (!plan.json.empty()) write_tradeoff_json(plan.json, rows);
    if (!plan.csv.empty()) write_tradeoff_csv(plan.csv, rows);
    std::fprintf(stderr, "raypack bench --tradeoff%s: %zu rows in %.1f s\n", plan.quick ? " --quick" : "", rows.size(),
                 stages.elapsed());
    return 0;
}

}  // namespace raypack::app
