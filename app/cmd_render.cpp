// raypack render SCENE [-o out.png] [--res W H] [--depth D] [--threads T] [--aov cost] [--offset POLICY]
//                [--json] [--quiet]
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <optional>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "accel/threads_spread.h"
#include "app/scene_options.h"
#include "app/accel_options.h"
#include "app/default_config.h"
#include "app/commands.h"
#include "app/variant_options.h"
#include "accel/counting_accel.h"
#include "measure/cost_map.h"
#include "render/path_tracer.h"
#include "render/ray_log.h"
#include "render/whitted.h"
#include "scene/load.h"
#include "scene/ray_file.h"
#include "scene/memory_budget.h"

namespace raypack::app {
namespace {

double ms_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

std::string default_output(const std::string& spec) {
    if (spec.rfind("gen:", 0) == 0) {
        std::string name = spec.substr(4);
        for (char& c : name)
            if (c == ':') c = '-';
        return name + ".png";
    }
    return std::filesystem::path(spec).stem().string() + ".png";
}

/// --aov cost: the heat map, and its scale on stdout.
int render_cost(const Scene& scene, const Accel& accel, int width, int height, const std::string& output) {
    const auto t0 = std::chrono::steady_clock::now();
    const CostMap map = primary_ray_cost(scene, accel, width, height);
    write_image(output, cost_heat_map(map));
    double sum = 0;
    for (std::uint32_t c : map.cost) sum += c;
    std::printf("raypack render --aov cost: %s, %s, %dx%d in %.1f ms\n", scene.source.c_str(),
                accel.stats().name.c_str(), width, height, ms_since(t0));
    std::printf("  scale      nodes + primitive tests per camera ray: %u (dark blue) .. %u (yellow), viridis, "
                "linear; mean %.1f\n",
                map.min, map.max, map.cost.empty() ? 0.0 : sum / double(map.cost.size()));
    std::printf("  image      %s (%dx%d, legend in the bottom %d rows)\n", std::filesystem::absolute(output).string().c_str(),
                width, height + cost_legend_height(width), cost_legend_height(width));
    return 0;
}

/// A progress line on a terminal, redrawn at most every 0.2 s once the
/// render has run for a second; nothing at all when stdout is not a terminal.
class ProgressLine {
public:
    explicit ProgressLine(bool enabled) : enabled_(enabled), start_(std::chrono::steady_clock::now()) {}

    static void report(void* self, std::uint64_t done, std::uint64_t total) {
        static_cast<ProgressLine*>(self)->update(done, total);
    }

    /// Clears the line if one was drawn.
    void finish() {
        if (drawn_) std::printf("\r%*s\r", 60, "");
        std::fflush(stdout);
    }

private:
    void update(std::uint64_t done, std::uint64_t total) {
        if (!enabled_) return;
        const double ms = ms_since(start_);
        if (ms < 1000) return;
        const std::lock_guard<std::mutex> lock(mutex_);
        if (ms - last_ms_ < 200 && done < total) return;
        last_ms_ = ms;
        const double fraction = double(done) / double(total);
        std::printf("\rrendering %5.1f%%, %.1f s elapsed, about %.1f s left", 100 * fraction, ms / 1000,
                    fraction > 0 ? ms / 1000 * (1 - fraction) / fraction : 0.0);
        std::fflush(stdout);
        drawn_ = true;
    }

    bool enabled_;
    std::chrono::steady_clock::time_point start_;
    std::mutex mutex_;
    double last_ms_ = 0;
    bool drawn_ = false;
};

}  // namespace

int run_render(const Args& args) {
    auto spec = accel_option_specs();
    spec.insert(spec.end(), {{"--output", "-o", 1}, {"--res", "", 2}, {"--depth", "", 1}, {"--threads", "", 1},
                             {"--aov", "", 1}, offset_option_spec(), {"--json", "", 0},
                             {"--quiet", "-q", 0}, {"--integrator", "", 1}, {"--spp", "", 1}, {"--sampler", "", 1},
                             {"--seed", "", 1}, {"--light-samples", "", 1}, {"--filter", "", 1},
                             {"--rr-depth", "", 1}, {"--exposure", "", 1}, {"--adaptive", "", 1},
                             {"--adaptive-depth", "", 1}, {"--counts", "", 0}, {"--save-rays", "", 1}, {"--tile", "", 1}});
    for (OptionSpec& k : scene_option_specs()) spec.push_back(std::move(k));
    const ParsedArgs p(args, spec, 1);
    if (p.help() || p.positional().empty()) {
        std::printf(
            "usage: raypack render SCENE [-o out.png] [--res W H] [--depth D] [--threads T] [--aov cost]\n"
            "                     [--offset POLICY] [structure and kernel options]\n"
            "  -o FILE       output image; format from the extension (png, exr, ...)\n"
            "  --res W H     resolution (default: the scene's, 512x512 for SPD)\n"
            "  --depth D     maximum ray depth, eye ray = 1 (default 5, the SPD protocol)\n"
            "  --threads T   worker threads (default: all cores)\n"
            "  --tile S      pixels per tile side, a tile's rays of one depth being one batch (default 16;\n"
            "                64 where streams carry the reflections: docs/renderer.md)\n"
            "  --aov cost    instead of shading: the traversal cost (nodes + primitive tests) of each\n"
            "                pixel's camera ray as a viridis heat map with its scale below the picture\n"
            "  --integrator whitted|distribution|path\n"
            "                whitted (default): one ray per pixel centre, pinhole, mirrors, each area light\n"
            "                one point; distribution: the samples below (Cook et al. 1984); path: path\n"
            "                tracing with next-event estimation, radiance units (docs/renderer.md)\n"
            "  --spp N       distribution, path: camera samples per pixel (default 16)\n"
            "  --rr-depth D  path: bounces before Russian roulette may end a path (default 3);\n"
            "                --depth caps the path (default 5)\n"
            "  --sampler regular|random|stratified|sobol   (default stratified)\n"
            "  --light-samples N  distribution: shadow rays per area light per sample (default 1)\n"
            "  --adaptive T  distribution: adaptive supersampling instead of --spp: pixel corners, and\n"
            "                squares whose corners differ by T split in four (POV-Ray's +AM2)\n"
            "  --adaptive-depth D  levels of splitting (default 3: down to 1/8 of a pixel)\n"
            "  --filter box|tent|gaussian  pixel filter (default box)\n"
            "  --seed S      random numbers of the samplers (default 1)\n"
            "  --exposure E  multiply the image by E before writing it (default 1)\n"
            "  --counts      trace every ray through the structure's counting walk (slower, the same\n"
            "                image) and report Havran's measures per ray over all the render's rays:\n"
            "                N_IT tests, N_TS traversal steps, N_ETS leaves or cells, N_EETS empty ones\n"
            "  --save-rays PREFIX  also write every ray the render traced, by kind, in the order it\n"
            "                traced them: PREFIX-eye.rays, PREFIX-bounce.rays (reflected, refracted, diffuse),\n"
            "                PREFIX-shadow.rays (docs/rays.md; kinds with no rays get no file), so that\n"
            "                `raypack trace` can time the render's own rays\n"
            "  --json        print one JSON line (times, ray counts, Mrays/s) instead of the text report\n"
            "  --quiet, -q   print nothing on success\n"
            "  A progress line is shown on a terminal for renders that take more than a second.\n%s",
            (accel_options_help() + scene_option_help()).c_str());
        if (!p.help()) throw UsageError("missing SCENE");
        return 0;
    }
    const std::string scene_spec = p.positional()[0];
    AccelConfig config = accel_config_from(p);
    // Eye rays are camera rays: with no structure named, the fastest for them.
    const bool fastest = uses_fastest_config(p);
    if (fastest) config.kind = fastest_config(RayWorkload::Camera).accel;
    WhittedOptions options;
    options.max_depth = int(p.integer("--depth", 5, 1, 64));
    options.tile_size = int(p.integer("--tile", 0, 1, 4096));
    options.offset = offset_policy_from(p);
    const std::string integrator = p.has("--integrator") ? p.text("--integrator") : "whitted";
    if (integrator != "whitted" && integrator != "distribution" && integrator != "path")
        throw UsageError("--integrator: expected whitted, distribution or path, got '" + integrator + "'");
    options.distribution = integrator != "whitted";
    for (const char* flag : {"--spp", "--sampler", "--light-samples", "--filter", "--seed"})
        if (p.has(flag) && !options.distribution)
            throw UsageError(std::string(flag) + " needs --integrator distribution or path");
    if (p.has("--rr-depth") && integrator != "path") throw UsageError("--rr-depth needs --integrator path");
    for (const char* flag : {"--adaptive", "--adaptive-depth"})
        if (p.has(flag) && integrator != "distribution") throw UsageError(std::string(flag) + " needs --integrator distribution");
    if (p.has("--adaptive") && p.has("--spp")) throw UsageError("--adaptive replaces --spp: give one of them");
    options.adaptive_threshold = float(p.number("--adaptive", 0, 0, 1e30));
    options.adaptive_depth = int(p.integer("--adaptive-depth", 3, 0, 8));
    if (p.has("--light-samples") && integrator == "path")
        throw UsageError("--light-samples: the path integrator takes one light sample per bounce");
    const float exposure = float(p.number("--exposure", 1.0, 0.0, 1e30));
    PathOptions path;
    path.rr_depth = int(p.integer("--rr-depth", 3, 0, 1 << 20));
    path.max_depth = int(p.integer("--depth", 5, 1, 1 << 20));
    options.spp = int(p.integer("--spp", 16, 1, 1 << 16));
    options.light_samples = int(p.integer("--light-samples", 1, 1, 1 << 12));
    options.seed = std::uint64_t(p.integer("--seed", 1, 0, (1ll << 62)));
    if (p.has("--sampler")) {
        const auto k = sampler_from_name(p.text("--sampler"));
        if (!k) throw UsageError("--sampler: expected regular|random|stratified|sobol, got '" + p.text("--sampler") + "'");
        options.sampler = *k;
    }
    if (p.has("--filter")) {
        const auto f = pixel_filter_from_name(p.text("--filter"));
        if (!f) throw UsageError("--filter: expected box|tent|gaussian, got '" + p.text("--filter") + "'");
        options.filter = *f;
    }
    const ThreadLimit limit(int(p.integer("--threads", 0, 1, 1024)));
    const std::string output = p.has("--output") ? p.text("--output") : default_output(scene_spec);
    const std::string aov = p.text("--aov");
    if (p.has("--aov") && aov != "cost") throw UsageError("--aov: expected cost, got '" + aov + "'");
    // The image module loads on the other core while the scene loads and the
    // structure builds: started later, it took a core from the render's
    // second thread (a 2-thread tetra render ran no faster than 1 thread).
    start_loading_image_module(output);
    // The render's second thread joins while the scene loads: its first
    // wake-up then lands on a CPU of its own (accel/threads_spread.h).
    ThreadsSpread::start_workers();

    auto t0 = std::chrono::steady_clock::now();
    const Scene scene = load_scene_from(p, scene_spec);
    const double load_ms = ms_since(t0);
    options.width = int(p.integer("--res", scene.camera.width, 1, 65536, 0));
    options.height = int(p.integer("--res", scene.camera.height, 1, 65536, 1));
    if (std::uint64_t(options.width) * std::uint64_t(options.height) > (1ull << 28))
        throw UsageError("--res: image of more than 2^28 pixels");
    // The image (12 bytes a pixel) and the film of a sampled render (sums,
    // sums of squares and counts: 28 bytes a pixel).
    require_memory(std::uint64_t(options.width) * std::uint64_t(options.height) * (options.distribution ? 40 : 12),
                   "a " + std::to_string(options.width) + " x " + std::to_string(options.height) + " image");

    // The image, and the film a sampled render adds its samples to, made
    // before the build: their fresh pages cost several ms to fault in on
    // this project's virtual machines (tens of ms when the kernel clears
    // huge pages), which is not rendering (render_ms), and which the second
    // thread cannot share (docs/renderer.md, "Threads").
    Image image;
    std::optional<Film> film;
    if (aov != "cost") {
        image = Image(options.width, options.height);
        if (integrator == "path" || (options.distribution && options.adaptive_threshold == 0 && options.spp > 1))
            options.film = &film.emplace(options.width, options.height);
    }
    const auto built = build_accel(scene, config);
    if (aov == "cost") return render_cost(scene, *built, options.width, options.height, output);
    // --counts: the render's queries through the counting walk, summed.
    const bool counting = p.has("--counts");
    if (counting && scene.features.motion)
        throw UsageError("--counts: a moving scene's rays carry times the counting walk does not take");
    std::optional<CountingAccel> counter;
    if (counting) {
        try {
            counter.emplace(*built);
        } catch (const std::invalid_argument& e) {
            throw UsageError(std::string("--counts: ") + e.what());
        }
    }
    const Accel* accel = counting ? static_cast<const Accel*>(&*counter) : built.get();
    options.packet = fastest ? supported_packet(*accel, fastest_config(RayWorkload::Camera).packet)
                             : packet_width_from(p, *accel);
    // Secondary rays: the widest packets (measured on balls, gears and
    // tetra, 1 thread: 16 beat 1 by 0-12%, 4 lost 10-30%), or --packet.
    options.secondary_packet = p.has("--packet") ? options.packet : supported_packet(*accel, 16);
    // --save-rays: every ray kept in memory until the render ends, at most
    // half of what the machine has free (a ray and its time: 36 bytes).
    std::optional<RayLog> ray_log;
    const std::string rays_prefix = p.text("--save-rays");
    if (p.has("--save-rays")) {
        if (rays_prefix.empty()) throw UsageError("--save-rays: expected a file prefix");
        const std::uint64_t available = available_memory();
        options.ray_log = &ray_log.emplace(available > 0 ? available / 2 / (sizeof(Rayf) + sizeof(float)) : 1ull << 27);
    }
    const bool json = p.has("--json"), quiet = p.has("--quiet");
    ProgressLine progress(!json && !quiet && ::isatty(STDOUT_FILENO));
    options.progress = &ProgressLine::report;
    options.progress_context = &progress;
    const RenderStats stats = integrator == "path" ? render_path(scene, *accel, options, path, image)
                                                   : render_whitted(scene, *accel, options, image);
    progress.finish();
    if (exposure != 1.0f)
        for (float& v : image.rgb) v *= exposure;
    t0 = std::chrono::steady_clock::now();
    write_image(output, image);
    const double write_ms = ms_since(t0);
    std::vector<std::string> saved_rays;
    if (ray_log)
        for (const RayLog::Kind kind : {RayLog::Eye, RayLog::Bounce, RayLog::Shadow}) {
            if (ray_log->rays(kind).empty()) continue;
            saved_rays.push_back(rays_prefix + "-" + RayLog::name(kind) + ".rays");
            write_rays(saved_rays.back(), kind == RayLog::Shadow ? RayKind::AnyHit : RayKind::ClosestHit,
                       ray_log->rays(kind), ray_log->times(kind));
        }
    const double mrays = stats.render_ms > 0 ? double(stats.total_rays()) / (stats.render_ms * 1e3) : 0.0;

    // --counts: Havran's measures per ray over every ray of the render.
    struct PerRay {
        double it, ts, ets, eets;
    };
    std::optional<PerRay> per_ray;
    if (counter) {
        const TraversalCounts c = counter->totals();
        const double n = double(std::max<std::uint64_t>(counter->rays(), 1));
        per_ray = PerRay{double(c.prims) / n, double(c.nodes) / n, double(c.leaves) / n, double(c.empty_leaves) / n};
    }

    const AccelStats& as = accel->stats();
    if (json) {
        nlohmann::json j;
        j["scene"] = scene.source;
        j["integrator"] = integrator;
        j["width"] = options.width;
        j["height"] = options.height;
        j["spp"] = options.distribution && options.adaptive_threshold == 0 ? options.spp : 1;
        if (integrator == "path") j["rr_depth"] = path.rr_depth;
        if (options.distribution) {
            j["sampler"] = sampler_name(options.sampler);
            if (integrator == "distribution") j["light_samples"] = options.light_samples;
            j["filter"] = pixel_filter_name(options.filter);
            j["seed"] = options.seed;
        }
        j["depth"] = options.max_depth;
        j["threads"] = limit.threads();
        j["accel"] = as.name;
        j["packet"] = options.packet;
        j["secondary_packet"] = options.secondary_packet;
        j["offset"] = offset_policy_name(options.offset);
        j["load_ms"] = load_ms;
        j["build_ms"] = as.build_ms;
        j["render_ms"] = stats.render_ms;
        j["write_ms"] = write_ms;
        j["rays"] = {{"eye", stats.eye_rays},
                     {"eye_hits", stats.eye_hits},
                     {"shadow", stats.shadow_rays},
                     {"reflect", stats.reflect_rays},
                     {"refract", stats.refract_rays},
                     {"diffuse", stats.diffuse_rays}};
        j["mrays_per_s"] = mrays;
        if (per_ray) {
            j["counted_rays"] = counter->rays();
            j["n_it"] = per_ray->it;
            j["n_ts"] = per_ray->ts;
            j["n_ets"] = per_ray->ets;
            j["n_eets"] = per_ray->eets;
        }
        if (options.distribution && options.adaptive_threshold == 0) j["noise_rms"] = stats.noise_rms;
        if (options.adaptive_threshold > 0) {
            j["adaptive"] = options.adaptive_threshold;
            j["adaptive_depth"] = options.adaptive_depth;
            j["samples_per_pixel"] = stats.samples_per_pixel;
        }
        j["output"] = std::filesystem::absolute(output).string();
        if (ray_log) j["saved_rays"] = saved_rays;
        std::printf("%s\n", j.dump().c_str());
        return 0;
    }
    if (quiet) return 0;
    std::printf("raypack render: %s\n", scene.source.c_str());
    std::printf("  scene      %zu primitives (%zu spheres, %zu triangles, %zu cones, %zu height fields), %zu lights, loaded in %.1f ms\n",
                scene.primitive_count(), scene.spheres.size(), scene.triangles.size(), scene.cones.size(),
                scene.height_fields.size(),
                scene.lights.size(), load_ms);
    std::printf("  structure  %s (%s), built in %.1f ms: %zu nodes, %zu leaves (%zu empty), depth %d, "
                "%.2f refs/prim, %.1f KiB, SAH cost %.2f\n",
                as.name.c_str(), as.builder.c_str(), as.build_ms, as.nodes, as.leaves, as.empty_leaves, as.depth,
                as.refs_per_prim, double(as.bytes) / 1024.0, as.sah_cost);
    if (!is_embree_kind(as.name)) std::printf("  kernels    %s\n", kernel_choice_summary(config.kernels).c_str());
    std::printf("  render     %dx%d, depth %d, %d threads, packets of %d (eye) and %d (secondary), offset %s, "
                "%s: %.1f ms, %.2f Mrays/s\n",
                options.width, options.height, options.max_depth, limit.threads(), options.packet,
                options.secondary_packet, offset_policy_name(options.offset),
                integrator == "path" ? "Path" : options.distribution ? "Distribution" : "Whitted", stats.render_ms,
                mrays);
    if (options.adaptive_threshold > 0)
        std::printf("  adaptive   threshold %g, depth %d: %.2f points per pixel\n", options.adaptive_threshold,
                    options.adaptive_depth, stats.samples_per_pixel);
    else if (options.distribution)
        std::printf("  noise      %.3g RMS standard error of the pixel means\n", stats.noise_rms);
    if (options.distribution && options.adaptive_threshold == 0)
        std::printf("  sampling   %d samples per pixel (%s, %s filter, seed %llu), %s\n", options.spp,
                    sampler_name(options.sampler), pixel_filter_name(options.filter),
                    (unsigned long long)options.seed,
                    integrator == "path" ? ("Russian roulette after " + std::to_string(path.rr_depth) + " bounces").c_str()
                                         : (std::to_string(options.light_samples) + " per area light").c_str());
    std::printf("  rays       eye %llu (%llu hit), reflect %llu, refract %llu, shadow %llu",
                (unsigned long long)stats.eye_rays, (unsigned long long)stats.eye_hits,
                (unsigned long long)stats.reflect_rays, (unsigned long long)stats.refract_rays,
                (unsigned long long)stats.shadow_rays);
    if (stats.diffuse_rays) std::printf(", diffuse %llu", (unsigned long long)stats.diffuse_rays);
    std::printf("\n");
    if (per_ray)
        std::printf("  counts     per ray over %llu rays: N_IT %.2f, N_TS %.2f, N_ETS %.2f, N_EETS %.2f\n",
                    (unsigned long long)counter->rays(), per_ray->it, per_ray->ts, per_ray->ets, per_ray->eets);
    std::printf("  image      %s (written in %.1f ms)\n", std::filesystem::absolute(output).string().c_str(), write_ms);
    for (const std::string& f : saved_rays) std::printf("  rays file  %s\n", std::filesystem::absolute(f).string().c_str());
    return 0;
}

}  // namespace raypack::app
