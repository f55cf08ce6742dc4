// raypack trace SCENE --rays FILE.rays [-o FILE.hits] [--threads T] [--repeat R] [--json]
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <vector>

#include "app/scene_options.h"
#include "app/accel_options.h"
#include "app/commands.h"
#include "app/default_config.h"
#include "accel/bvh/wide_packet.h"
#include "accel/kdtree/kdtree_packet.h"
#include "accel/octree/octree_packet.h"
#include "accel/threads_spread.h"
#include "scene/load.h"
#include "scene/ray_file.h"

namespace raypack::app {
namespace {

// Rays per call into the structure: 16 of the packet loop's loads of 256
// rays, so that each load's walk can ask for the next one's rays
// (trace_in_groups, accel/packet_driver.h).
constexpr std::size_t kBatch = 4096;

/// One pass over all rays, batches in parallel (each one stream with
/// `stream`), into `hits` (closest hit) or `occluded` (any hit, one byte a
/// ray, as the structures answer: Embree's timed passes likewise leave
/// their answers where the query puts them, bench/tools/embree_direct.cpp);
/// returns milliseconds.
double trace_all(const Accel& accel, int packet, bool stream, const RayFile& file, std::vector<Hitf>& hits,
                 std::vector<std::uint8_t>& occluded) {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t n = file.rays.size();
    ThreadsSpread spread;  // one CPU per thread
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, (n + kBatch - 1) / kBatch), [&](const auto& r) {
        spread.enter();
        for (std::size_t b = r.begin(); b < r.end(); ++b) {
            const std::size_t lo = b * kBatch, hi = std::min(n, lo + kBatch);
            const std::span<const Rayf> rays(file.rays.data() + lo, hi - lo);
            // Version 2 files: each ray at its time.
            const std::span<const float> times =
                file.times.empty() ? std::span<const float>{} : std::span<const float>(file.times.data() + lo, hi - lo);
            if (file.kind == RayKind::ClosestHit) {
                const std::span<Hitf> out(hits.data() + lo, hi - lo);
                if (!times.empty()) accel.intersect_at(packet, rays, times, out);
                else if (stream) accel.intersect_stream(packet, rays, out);
                else accel.intersect_packets(packet, rays, out);
            } else {
                const std::span<std::uint8_t> out(occluded.data() + lo, hi - lo);
                if (!times.empty()) accel.occluded_at(packet, rays, times, out);
                else if (stream) accel.occluded_stream(packet, rays, out);
                else accel.occluded_packets(packet, rays, out);
            }
        }
    });
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int run_trace(const Args& args) {
    auto spec = accel_option_specs();
    for (OptionSpec& k : scene_option_specs()) spec.push_back(std::move(k));
    spec.insert(spec.end(), {{"--rays", "", 1}, {"--output", "-o", 1}, {"--threads", "", 1}, {"--repeat", "", 1},
                             {"--json", "", 0}, {"--stream", "", 0}});
    const ParsedArgs p(args, spec, 1);
    if (p.help() || p.positional().empty()) {
        std::printf(
            "usage: raypack trace SCENE --rays FILE.rays [-o FILE.hits] [--threads T] [--repeat R] [--stream] [--json]\n"
            "  --rays FILE   rays to trace (docs/rays.md); kind 1 files answer occlusion\n"
            "  -o FILE       write the hits (docs/rays.md)\n"
            "  --repeat R    timed passes after one untimed warm-up (default 5); the median is reported\n"
            "  --threads T   worker threads (default: all cores)\n"
            "  --stream      each batch of 4096 rays walks the structure as one stream (bvh4, bvh8 with\n"
            "                AVX-512; docs/structures.md): for incoherent rays; batches under 256 go as packets\n"
            "  --json        print one JSON line instead of text\n%s",
            (accel_options_help() + scene_option_help()).c_str());
        if (!p.help()) throw UsageError("missing SCENE");
        return 0;
    }
    if (!p.has("--rays")) throw UsageError("missing --rays FILE.rays");
    AccelConfig config = accel_config_from(p);
    const int repeat = int(p.integer("--repeat", 5, 1, 100000));
    const ThreadLimit limit(int(p.integer("--threads", 0, 1, 1024)));

    const Scene scene = load_scene_from(p, p.positional()[0]);
    const RayFile file = read_rays(p.text("--rays"));
    const RayWorkload workload = classify_workload(file.rays, file.kind == RayKind::AnyHit);
    const bool fastest = uses_fastest_config(p);
    if (fastest) config.kind = fastest_config(workload).accel;
    const auto accel = build_accel(scene, config);
    const int packet = fastest ? supported_packet(*accel, fastest_config(workload).packet) : packet_width_from(p, *accel);
    const bool stream = p.has("--stream") || (fastest && fastest_config(workload).stream && accel->supports_stream());
    if (stream && !accel->supports_stream())
        throw UsageError("--stream: " + accel->stats().name +
                         " has no stream traversal in this build (bvh4 and bvh8 with AVX-512 have)");
    if (stream && !file.times.empty()) throw UsageError("--stream: rays at times (a version 2 file) go as packets");
    const bool any_hit = file.kind != RayKind::ClosestHit;
    std::vector<Hitf> hits(file.rays.size());
    std::vector<std::uint8_t> occluded(any_hit ? file.rays.size() : 0);
    trace_all(*accel, packet, stream, file, hits, occluded);  // warm-up, untimed
    std::vector<double> times;
    for (int r = 0; r < repeat; ++r) times.push_back(trace_all(*accel, packet, stream, file, hits, occluded));
    if (any_hit)
        for (std::size_t i = 0; i < hits.size(); ++i) {
            hits[i] = Hitf{};
            if (occluded[i]) hits[i].prim = 0;  // rays.md: 0 = occluded
        }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted.size() % 2 ? sorted[sorted.size() / 2]
                                            : 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
    const std::size_t hit_count =
        std::size_t(std::count_if(hits.begin(), hits.end(), [](const Hitf& h) { return h.found(); }));
    if (p.has("--output")) write_hits(p.text("--output"), hits);

    const double rays = double(file.rays.size());
    const double mrays = median > 0 ? rays / (median * 1e3) : 0.0;
    const AccelStats& as = accel->stats();
    if (p.has("--json")) {
        nlohmann::json j;
        j["scene"] = scene.source;
        j["accel"] = as.name;
        j["builder"] = as.builder;
        j["packet"] = packet;
        j["stream"] = stream;
        // Packets per shared walk, at most (1: alone). The k-d tree groups
        // rays from one point (robust slabs), the octree rays of one octant,
        // both in float precision; both keep the rest alone.
        const bool wide = (as.name == "bvh4" || as.name == "bvh8") && packet > 1;
        const bool cells = (as.name == "octree" || (as.name == "kdtree" && config.kernels.slabs == SlabMethod::Robust)) &&
                           packet > 1 && config.packet_group != 1 && config.kernels.precision == Precision::Float;
        j["group"] = wide    ? (config.packet_group > 0 ? config.packet_group
                                                        : default_wide_packet_config(4, packet).group_packets)
                     : cells ? (as.name == "kdtree" ? kKdGroupPackets : octree_group_packets(packet))
                             : 1;
        j["triangle"] = triangle_method_name(config.kernels.triangle);
        j["sphere"] = sphere_method_name(config.kernels.sphere);
        j["slabs"] = slab_method_name(config.kernels.slabs);
        j["rcp"] = rcp_method_name(config.kernels.rcp);
        j["precision"] = precision_name(config.kernels.precision);
        j["features"] = feature_names(scene.features);
        j["specialisation"] = specialisation_name(as.specialisation);
        j["default_config"] = fastest;  // chosen by the measured table, not the command line
        j["workload"] = workload_name(workload);
        j["kind"] = file.kind == RayKind::ClosestHit ? "closest" : "any";
        j["rays"] = file.rays.size();
        j["threads"] = limit.threads();
        j["repeat"] = repeat;
        j["build_ms"] = as.build_ms;
        j["memory_bytes"] = as.bytes;
        j["bytes_per_prim"] = as.bytes_per_prim();
        j["nodes"] = as.nodes;
        j["leaves"] = as.leaves;
        j["empty_leaves"] = as.empty_leaves;
        j["depth"] = as.depth;
        j["refs_per_prim"] = as.refs_per_prim;
        j["sah_cost"] = as.sah_cost;
        j["trace_ms_median"] = median;
        j["trace_ms_min"] = sorted.front();
        j["trace_ms_max"] = sorted.back();
        j["mrays_per_s_median"] = mrays;
        j["hits"] = hit_count;
        std::printf("%s\n", j.dump().c_str());
    } else {
        std::printf("raypack trace: %s, %zu %s rays, %s (%s) built in %.1f ms\n", scene.source.c_str(),
                    file.rays.size(), file.kind == RayKind::ClosestHit ? "closest-hit" : "any-hit", as.name.c_str(),
                    as.builder.c_str(), as.build_ms);
        if (!is_embree_kind(as.name))
            std::printf("  kernels: %s; loops for %s primitives\n", kernel_choice_summary(config.kernels).c_str(),
                        specialisation_name(as.specialisation));
        std::printf("  %s of %d, %d threads, %d passes: median %.2f ms (min %.2f, max %.2f), %.2f Mrays/s; %zu %s\n",
                    stream ? "streams of batches, else packets" : "packets", packet, limit.threads(), repeat, median, sorted.front(), sorted.back(), mrays, hit_count,
                    file.kind == RayKind::ClosestHit ? "hits" : "occluded");
        if (fastest)
            std::printf("  (%s rays: the fastest measured configuration; --accel/--packet/--builder choose another)\n",
                        workload_name(workload));
    }
    return 0;
}

}  // namespace raypack::app
