// raypack bench [SCENE...] [--accel LIST] [--packet LIST] [--rays KINDS | --rays-file FILE]
//               [--threads LIST] [--repeat R] [--res W H] [--offset POLICY] [--json FILE] [--csv FILE] [--quick]
// raypack bench --tradeoff [--quick] [--repeat R] [--json FILE] [--csv FILE]: app/bench_tradeoff.h
// Every structure, packet width and ray kind on the same scenes; each case
// is checked against the brute-force oracle before it is timed (tinybvh's
// ValidateTraceResult; Mitsuba's ray_intersect_naive), and a mismatch is an
// error, never a row.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "accel/bvh/bvh_builders.h"
#include "app/scene_options.h"
#include "app/accel_options.h"
#include "app/bench_html.h"
#include "app/bench_measure.h"
#include "app/bench_report.h"
#include "app/bench_tradeoff.h"
#include "app/commands.h"
#include "app/variant_options.h"
#include "measure/cost_map.h"
#include "scene/load.h"

namespace raypack::app {
namespace {

constexpr std::size_t kOracleRays = 2048;   // rays checked against brute force per case
constexpr std::size_t kCountedRays = 65536; // rays walked by the counting traversal per case
constexpr int kPacketWidths[] = {1, 4, 8, 16};

std::vector<std::string> split_list(const std::string& list) {
    std::vector<std::string> items;
    std::stringstream in(list);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) items.push_back(item);
    return items;
}

std::vector<int> integer_list(const ParsedArgs& p, const std::string& flag, int lo, int hi) {
    std::vector<int> values;
    for (const std::string& item : split_list(p.text(flag))) {
        char* end = nullptr;
        const long v = std::strtol(item.c_str(), &end, 10);
        if (*end != '\0' || v < lo || v > hi)
            throw UsageError(flag + ": expected integers between " + std::to_string(lo) + " and " + std::to_string(hi) +
                             ", got '" + item + "'");
        values.push_back(int(v));
    }
    if (values.empty()) throw UsageError(flag + ": empty list");
    return values;
}

/// "balls" for gen:balls:4, "bunny" for scenes/bunny.obj.
std::string short_scene_name(const std::string& spec) {
    if (spec.rfind("gen:", 0) == 0) return spec.substr(4, spec.find(':', 4) - 4);
    return std::filesystem::path(spec).stem().string();
}

struct BenchPlan {
    std::vector<std::string> scenes, accels, ray_kinds;
    std::vector<int> packets;  ///< empty: 1 and every width each structure traverses natively
    std::vector<int> threads{1};
    std::string rays_file;
    int repeat = 5, width = 512, height = 512;
    OffsetPolicy offset = kDefaultOffset;
    KernelChoice kernels;        ///< --triangle, --sphere, --slabs, --precision, --rcp (not Embree's)
    std::string builder = "binned";  ///< --builder, for bvh2, bvh4, bvh8
    std::string embree_quality = "medium";  ///< --embree-quality, for embree and embree-robust
    bool quick = false;

    /// Embree runs its own tests in float (Moeller triangles) whatever
    /// --triangle, --sphere, --precision say, so it is checked against the
    /// default oracle, as without them.
    bool embree_needs_own_oracle() const {
        const KernelChoice d;
        return std::any_of(accels.begin(), accels.end(), [](const std::string& a) { return is_embree_kind(a); }) &&
               (kernels.triangle != d.triangle || kernels.sphere != d.sphere || kernels.precision != d.precision);
    }

    AccelConfig config(const std::string& kind) const {
        AccelConfig c = accel_config(kind, kernels);
        c.builder = builder;
        c.build_quality = embree_quality;
        return c;
    }
};

void print_help() {
    std::printf(
        "usage: raypack bench [SCENE...] [--accel LIST] [--packet LIST] [--rays KINDS | --rays-file FILE]\n"
        "                     [--threads LIST] [--repeat R] [--res W H] [--offset POLICY] [--json FILE] [--csv FILE]\n"
        "                     [--report FILE.html] [--builder B] [--triangle T] [--sphere S] [--slabs S]\n"
        "                     [--precision P] [--rcp R] [--quick]\n"
        "       raypack bench --tradeoff [--quick] [--repeat R] [--json FILE] [--csv FILE]\n"
        "  SCENE          .nff, .obj or gen:NAME:SIZE (default gen:balls:4)\n"
        "  --accel LIST   comma-separated, from %s (default: all but brute,\n"
        "                 which is the oracle and takes minutes on large scenes)\n"
        "  --packet LIST  packet widths (default: 1 and every width the structure traverses natively;\n"
        "                 widths a structure lacks are skipped and listed)\n"
        "  --rays KINDS   camera,shadow,diffuse (default all three; diffuse: seed 1)\n"
        "  --rays-file F  trace a docs/rays.md file instead (one scene only)\n"
        "  --threads LIST worker thread counts (default 1)\n"
        "  --repeat R     timed passes after one warm-up; median, min and max reported (default 5)\n"
        "  --res W H      image size of the generated ray sets (default 512 512)\n"
        "  --json FILE    one object per row; --csv FILE: the same columns (schema: docs/bench.md)\n"
        "  --report FILE  one self-contained HTML page: the tables, a chart per scene and ray kind, the\n"
        "                 camera rays' cost heat maps, Havran's measures beside Havran and Sixta's (1999)\n"
        "  --quick        every structure (brute too), width and ray kind on gen:balls:3 at 256x256,\n"
        "                 repeat 3: the CI smoke run; explicit options still apply\n"
        "  --offset P     secondary-ray origins of the shadow and diffuse sets: %s (default %s)\n"
        "  --builder B    BVH builder of bvh2, bvh4, bvh8: %s (default binned)\n"
        "  --embree-quality Q  build quality of embree (Embree's fast mode) and embree-robust:\n"
        "                 low|medium|high (default medium, Embree's own)\n"
        "  kernel variants of every structure but Embree (which runs its own):\n%s"
        "  --tradeoff     speed against accuracy of each triangle, sphere, slab, rcp, precision, builder\n"
        "                 and offset variant: throughput, leaks at shared edges and vertices, t error\n"
        "                 in ULPs, self-intersections from scale 1e-4 to 1e6, image error against a\n"
        "                 double reference (docs/accuracy.md)\n",
        accel_kinds_list().c_str(), offset_policy_list().c_str(), offset_policy_name(kDefaultOffset),
        bvh_builder_list().c_str(), (kernel_options_help() + scene_option_help()).c_str());
}

BenchPlan plan_from(const ParsedArgs& p) {
    BenchPlan plan;
    plan.quick = p.has("--quick");
    plan.scenes = p.positional();
    if (plan.scenes.empty()) plan.scenes = {plan.quick ? "gen:balls:3" : "gen:balls:4"};
    if (plan.quick) plan.width = plan.height = 256, plan.repeat = 3;
    plan.width = int(p.integer("--res", plan.width, 1, 16384, 0));
    plan.height = int(p.integer("--res", plan.height, 1, 16384, 1));
    plan.repeat = int(p.integer("--repeat", plan.repeat, 1, 100000));
    if (p.has("--accel")) {
        plan.accels = split_list(p.text("--accel"));
        for (const std::string& a : plan.accels)
            if (std::none_of(accel_kinds().begin(), accel_kinds().end(), [&](const char* k) { return a == k; }))
                throw UsageError("--accel: unknown structure '" + a + "' (expected " + accel_kinds_list() + ")");
        if (plan.accels.empty()) throw UsageError("--accel: empty list");
    } else {
        for (const char* k : accel_kinds())
            if (plan.quick || std::string(k) != "brute") plan.accels.push_back(k);
    }
    if (p.has("--packet")) {
        plan.packets = integer_list(p, "--packet", 1, 16);
        for (int w : plan.packets)
            if (std::find(std::begin(kPacketWidths), std::end(kPacketWidths), w) == std::end(kPacketWidths))
                throw UsageError("--packet: expected widths from 1, 4, 8, 16, got " + std::to_string(w));
    }
    if (p.has("--threads")) plan.threads = integer_list(p, "--threads", 1, 1024);
    if (p.has("--rays") && p.has("--rays-file")) throw UsageError("--rays and --rays-file exclude each other");
    plan.rays_file = p.text("--rays-file");
    if (!plan.rays_file.empty() && plan.scenes.size() != 1)
        throw UsageError("--rays-file: give exactly one SCENE (the rays were made for one scene)");
    plan.ray_kinds = split_list(p.text("--rays", "camera,shadow,diffuse"));
    if (plan.ray_kinds.empty()) throw UsageError("--rays: empty list");
    for (const std::string& k : plan.ray_kinds)
        if (k != "camera" && k != "shadow" && k != "diffuse")
            throw UsageError("--rays: expected camera, shadow or diffuse, got '" + k + "'");
    if (!plan.rays_file.empty()) plan.ray_kinds = {"file"};
    plan.offset = offset_policy_from(p);
    plan.kernels = kernel_choice_from(p);
    if (p.has("--builder")) {
        plan.builder = p.text("--builder");
        if (!is_bvh_builder(plan.builder))
            throw UsageError("--builder: unknown builder '" + plan.builder + "' (expected " + bvh_builder_list() + ")");
    }
    std::string accel_list;
    for (const std::string& a : plan.accels) accel_list += a + ",";
    plan.embree_quality = embree_quality_from(p, accel_list);
    return plan;
}

/// The widths of `plan` that `accel` runs natively; the others are noted in `skipped`.
std::vector<int> packet_widths(const BenchPlan& plan, const Accel& accel, std::vector<std::string>& skipped) {
    std::vector<int> widths;
    for (int w : plan.packets.empty() ? std::vector<int>(std::begin(kPacketWidths), std::end(kPacketWidths))
                                      : plan.packets) {
        if (accel.supports_packet(w)) widths.push_back(w);
        else if (!plan.packets.empty()) skipped.push_back(accel.stats().name + " K=" + std::to_string(w) + " (not native)");
    }
    return widths;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Progress on stderr: the case, how many are done and the time since the start.
class Progress {
public:
    explicit Progress(std::size_t total) : total_(total) {}
    void next(const std::string& what) {
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        std::fprintf(stderr, "[%zu/%zu] %s, %.1f s elapsed\n", ++done_, total_, what.c_str(), s);
    }
    double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

private:
    std::size_t total_, done_ = 0;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// Cases per scene: widths do not depend on the scene, so a one-sphere
/// scene tells each structure's widths before anything large is built.
std::size_t count_cases(const BenchPlan& plan) {
    const Scene probe = load_scene("gen:balls:1");
    std::size_t per_scene = 0;
    std::vector<std::string> ignored;
    for (const std::string& a : plan.accels)
        per_scene += packet_widths(plan, *build_accel(probe, plan.config(a)), ignored).size();
    return per_scene * plan.scenes.size() * plan.ray_kinds.size() * plan.threads.size();
}

}  // namespace

int run_bench(const Args& args) {
    std::vector<OptionSpec> specs = {{"--accel", "", 1}, {"--packet", "", 1}, {"--rays", "", 1},
                                     {"--rays-file", "", 1}, {"--threads", "", 1}, {"--repeat", "", 1},
                                     {"--res", "", 2}, {"--json", "", 1}, {"--csv", "", 1}, {"--report", "", 1},
                                     {"--quick", "", 0}, {"--tradeoff", "", 0}, {"--builder", "", 1}, {"--embree-quality", "", 1},
                                     offset_option_spec()};
    for (OptionSpec& k : kernel_option_specs()) specs.push_back(std::move(k));
    for (OptionSpec& k : scene_option_specs()) specs.push_back(std::move(k));
    const ParsedArgs p(args, specs, 1000);
    if (p.help()) {
        print_help();
        return 0;
    }
    if (p.has("--tradeoff")) {
        for (const char* other : {"--accel", "--packet", "--rays", "--rays-file", "--threads", "--res", "--offset",
                                  "--report", "--builder", "--sphere", "--triangle", "--slabs", "--precision", "--rcp",
                                  "--embree-quality"})
            if (p.has(other)) throw UsageError(std::string(other) + " does not apply to --tradeoff (it runs every variant)");
        if (!p.positional().empty()) throw UsageError("--tradeoff takes no SCENE (it builds its own)");
        return run_tradeoff(TradeoffPlan{.quick = p.has("--quick"),
                                         .repeat = int(p.integer("--repeat", p.has("--quick") ? 3 : 9, 1, 1000)),
                                         .json = p.text("--json"), .csv = p.text("--csv")});
    }
    const BenchPlan plan = plan_from(p);
    BenchHtmlContext html;
    if (p.has("--report")) {
        html.command = "raypack bench";
        for (const std::string& t : args.tokens) html.command += " " + t;
        html.machine = processor_name();
    }
    Progress progress(count_cases(plan));
    std::vector<BenchRow> rows;
    std::vector<std::string> skipped;
    std::printf("kernels: %s; builder %s (Embree runs its own)\n", kernel_choice_summary(plan.kernels).c_str(),
                plan.builder.c_str());
    print_bench_header(stdout);
    for (const std::string& scene_spec : plan.scenes) {
        const Scene scene = load_scene_from(p, scene_spec);
        const std::string scene_name = short_scene_name(scene_spec);
        // Ray sets and oracle answers once per scene, shared by every structure.
        std::vector<BenchRays> sets;
        std::vector<OracleSample> samples, embree_samples;  // Embree runs the default tests
        for (const std::string& kind : plan.ray_kinds) {
            sets.push_back(kind == "file" ? load_bench_rays(plan.rays_file)
                                          : make_bench_rays(scene, kind, plan.width, plan.height, plan.offset));
            samples.push_back(oracle_sample(scene, sets.back(), kOracleRays, plan.kernels));
            if (plan.embree_needs_own_oracle())
                embree_samples.push_back(oracle_sample(scene, sets.back(), kOracleRays));
        }
        for (const std::string& accel_kind : plan.accels) {
            const auto accel = build_accel(scene, plan.config(accel_kind));
            const AccelStats& stats = accel->stats();
            if (p.has("--report") && !is_embree_kind(accel_kind) && accel_kind != "brute") {
                // The report's heat map: small, so that the page stays light.
                // Structures that cannot count (instanced or moving scenes) have none.
                constexpr int kMapSize = 128;
                try {
                    html.maps.push_back({scene_name, stats.name,
                                         cost_heat_map(primary_ray_cost(scene, *accel, kMapSize, kMapSize))});
                } catch (const std::runtime_error&) {
                }
            }
            const std::vector<int> widths = packet_widths(plan, *accel, skipped);
            for (std::size_t s = 0; s < sets.size(); ++s) {
                const BenchRays& set = sets[s];
                if (set.rays.empty()) {  // e.g. shadow rays in a scene without lights
                    skipped.push_back(scene_name + " " + set.name + " (no rays)");
                    continue;
                }
                const std::optional<WorkPerRay> work = work_per_ray(*accel, set, kCountedRays);
                for (int packet : widths) {
                    const std::string context =
                        scene_name + " " + accel_kind + " K=" + std::to_string(packet) + " " + set.name;
                    const bool embree_own = is_embree_kind(accel_kind) && plan.embree_needs_own_oracle();
                    validate_against_oracle(*accel, packet, set, embree_own ? embree_samples[s] : samples[s], context);
                    for (int threads : plan.threads) {
                        progress.next(context + " " + std::to_string(threads) + " thread" + (threads > 1 ? "s" : ""));
                        const ThreadLimit limit(threads);
                        BenchRow row;
                        row.scene = scene_name, row.scene_file = scene_spec, row.accel = stats.name;
                        row.builder = stats.builder, row.packet = packet, row.rays = set.name;
                        row.any_hit = set.any_hit, row.ray_count = set.rays.size(), row.threads = threads;
                        row.repeat = plan.repeat, row.build_ms = stats.build_ms, row.memory_bytes = stats.bytes;
                        row.sah_cost = stats.sah_cost;
                        const std::vector<double> ms = time_passes(*accel, packet, set, plan.repeat, row.hits);
                        // Mrays/s of each pass: the fastest pass is the max.
                        const double mrays = double(set.rays.size()) / 1e3;
                        row.trace_ms_median = median(ms);
                        row.mrays_per_s_median = row.trace_ms_median > 0 ? mrays / row.trace_ms_median : 0;
                        row.mrays_per_s_min = mrays / *std::max_element(ms.begin(), ms.end());
                        row.mrays_per_s_max = mrays / std::max(1e-9, *std::min_element(ms.begin(), ms.end()));
                        if (work) {
                            row.n_it = work->n_it;
                            row.n_ts = work->n_ts;
                            row.n_ets = work->n_ets;
                            row.n_eets = work->n_eets;
                        }
                        row.validated_rays = samples[s].rays.size();
                        row.validated = true;
                        print_bench_row(stdout, row);
                        std::fflush(stdout);
                        rows.push_back(std::move(row));
                    }
                }
            }
        }
    }
    std::sort(skipped.begin(), skipped.end());
    skipped.erase(std::unique(skipped.begin(), skipped.end()), skipped.end());
    if (!skipped.empty()) {
        std::printf("skipped:");
        for (const std::string& s : skipped) std::printf(" %s;", s.c_str());
        std::printf("\n");
    }
    if (p.has("--json")) write_bench_json(p.text("--json"), rows);
    if (p.has("--csv")) write_bench_csv(p.text("--csv"), rows);
    if (p.has("--report")) write_bench_html(p.text("--report"), rows, html);
    std::fprintf(stderr, "raypack bench: %zu rows in %.1f s\n", rows.size(), progress.elapsed());
    return 0;
}

}  // namespace raypack::app
