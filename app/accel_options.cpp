#include "app/accel_options.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "accel/bvh/bvh_builders.h"
#include "accel/bvh/wide_packet.h"

namespace raypack::app {

std::vector<OptionSpec> accel_option_specs() {
    std::vector<OptionSpec> specs = {{"--accel", "", 1}, {"--packet", "", 1}, {"--builder", "", 1},
                                       {"--embree-quality", "", 1}, {"--group", "", 1}};
    for (OptionSpec& k : kernel_option_specs()) specs.push_back(std::move(k));
    return specs;
}

namespace {

template <class E>
struct Named {
    const char* name;
    E value;
};

constexpr Named<SphereMethod> kSphereNames[] = {
    {"geometric", SphereMethod::Geometric}, {"algebraic", SphereMethod::Algebraic}, {"precise", SphereMethod::Precise}};
constexpr Named<TriangleMethod> kTriangleNames[] = {
    {"moeller", TriangleMethod::Moeller}, {"watertight", TriangleMethod::Watertight}, {"plane", TriangleMethod::Plane}};
constexpr Named<SlabMethod> kSlabNames[] = {{"robust", SlabMethod::Robust}, {"plain", SlabMethod::Plain}};
constexpr Named<Precision> kPrecisionNames[] = {{"float", Precision::Float}, {"double", Precision::Double}};
constexpr Named<RcpMethod> kRcpNames[] = {{"exact", RcpMethod::Exact}, {"approx", RcpMethod::Approx}};
constexpr Named<bool> kSpecialiseNames[] = {{"on", true}, {"off", false}};

/// The value `option` names, or its default (the first entry) without it.
template <class E, std::size_t N>
E parse_named(const ParsedArgs& args, const char* option, const Named<E> (&names)[N]) {
    if (!args.has(option)) return names[0].value;
    const std::string text = args.text(option);
    std::string expected;
    for (const Named<E>& n : names) {
        if (text == n.name) return n.value;
        if (!expected.empty()) expected += '|';
        expected += n.name;
    }
    throw UsageError(std::string(option) + ": expected " + expected + ", got '" + text + "'");
}

template <class E, std::size_t N>
const char* name_of(E value, const Named<E> (&names)[N]) {
    for (const Named<E>& n : names)
        if (n.value == value) return n.name;
    return "?";
}

}  // namespace

const char* sphere_method_name(SphereMethod m) { return name_of(m, kSphereNames); }
const char* triangle_method_name(TriangleMethod m) { return name_of(m, kTriangleNames); }
const char* slab_method_name(SlabMethod m) { return name_of(m, kSlabNames); }
const char* precision_name(Precision p) { return name_of(p, kPrecisionNames); }
const char* rcp_method_name(RcpMethod m) { return name_of(m, kRcpNames); }

std::string kernel_choice_summary(const KernelChoice& k) {
    return std::string(triangle_method_name(k.triangle)) + " triangles, " + sphere_method_name(k.sphere) +
           " spheres, " + slab_method_name(k.slabs) + " slabs, " + rcp_method_name(k.rcp) + " rcp, " +
           precision_name(k.precision);
}

std::string accel_options_help() {
    return "  With none of --accel, --builder, --packet: the fastest measured configuration for the rays\n"
           "  (camera: bvh4 --packet 16, shadow: bvh8 --packet 16, diffuse: bvh4 --packet 16, in trace as\n"
           "  streams; without AVX-512 packets of 8 and diffuse bvh8 --packet 1; docs/embree.md)\n"
           "  --accel " + accel_kinds_list() + "  acceleration structure (default bvh2)\n"
           "  --builder " + bvh_builder_list() + "  BVH builder for bvh2|bvh4|bvh8 (default binned):\n"
           "                binned SAH, full-sweep SAH, Morton/LBVH, spatial splits (SBVH)\n"
           "  --embree-quality low|medium|high  Embree's build quality (default medium, Embree's own);\n"
           "                embree is Embree's fast mode, embree-robust its robust mode\n"
           + kernel_options_help() +
           "  --packet 1|4|8|16             rays per packet (default 1; 16 needs AVX-512)\n"
           "  --group G                     bvh4|bvh8: packets that walk the tree together when their\n"
           "                rays share a direction octant (default 128 rays' worth; 1: each alone);\n"
           "                kdtree|octree: 1 makes each packet walk alone (default: groups of 16 / 8)\n";
}

std::vector<OptionSpec> kernel_option_specs() {
    return {{"--sphere", "", 1},    {"--triangle", "", 1}, {"--slabs", "", 1},
            {"--precision", "", 1}, {"--rcp", "", 1},      {"--specialise", "", 1}};
}

KernelChoice kernel_choice_from(const ParsedArgs& args) {
    KernelChoice k;
    k.sphere = parse_named(args, "--sphere", kSphereNames);
    k.triangle = parse_named(args, "--triangle", kTriangleNames);
    k.slabs = parse_named(args, "--slabs", kSlabNames);
    k.precision = parse_named(args, "--precision", kPrecisionNames);
    k.rcp = parse_named(args, "--rcp", kRcpNames);
    k.specialise = parse_named(args, "--specialise", kSpecialiseNames);
    return k;
}

std::string kernel_options_help() {
    return "  --sphere geometric|algebraic|precise     ray-sphere test (default geometric)\n"
           "  --triangle moeller|watertight|plane     ray-triangle test (default moeller)\n"
           "  --slabs robust|plain          box test of the traversal (default robust: Ize 2013)\n"
           "  --rcp exact|approx            reciprocal directions: division, or rcp + one Newton step\n"
           "  --precision float|double      arithmetic of the primitive tests (default float)\n"
           "  --specialise on|off           bvh4/bvh8 on a scene of triangles alone run loops compiled\n"
           "                for triangles alone (default on); off: the general loops, for comparison\n";
}

AccelConfig accel_config_from(const ParsedArgs& args) {
    AccelConfig config;
    config.kind = args.text("--accel", "bvh2");
    bool known = false;
    for (const char* k : accel_kinds()) known |= config.kind == k;
    if (!known)
        throw UsageError("--accel: unknown structure '" + config.kind + "' (expected " + accel_kinds_list() + ")");
    if (args.has("--builder")) {
        config.builder = args.text("--builder");
        if (!is_bvh_builder(config.builder))
            throw UsageError("--builder: unknown builder '" + config.builder + "' (expected " + bvh_builder_list() + ")");
        if (config.kind != "bvh2" && config.kind != "bvh4" && config.kind != "bvh8")
            throw UsageError("--builder applies to bvh2, bvh4 and bvh8 only, not to --accel " + config.kind);
    }
    if (args.has("--group")) {
        config.packet_group = int(args.integer("--group", 1, 1, WidePacketConfig::kMaxGroupPackets));
        const bool fixed_groups = config.kind == "kdtree" || config.kind == "octree";
        if (fixed_groups && config.packet_group != 1)
            throw UsageError("--group: " + config.kind +
                             " packets walk in groups of a fixed size; only --group 1 (each packet alone) applies");
        if (!uses_fastest_config(args) && config.kind != "bvh4" && config.kind != "bvh8" && !fixed_groups)
            throw UsageError("--group applies to bvh4, bvh8, kdtree and octree only, not to --accel " + config.kind);
    }
    config.kernels = kernel_choice_from(args);
    config.build_quality = embree_quality_from(args, config.kind);
    if (is_embree_kind(config.kind))
        for (const OptionSpec& option : kernel_option_specs())
            if (args.has(option.name))
                throw UsageError(option.name + " does not apply to --accel " + config.kind +
                                 " (Embree runs its own tests)");
    return config;
}

std::string embree_quality_from(const ParsedArgs& args, const std::string& accels) {
    if (!args.has("--embree-quality")) return "medium";
    const std::string quality = args.text("--embree-quality");
    if (quality != "low" && quality != "medium" && quality != "high")
        throw UsageError("--embree-quality: expected low|medium|high, got '" + quality + "'");
    if (accels.find("embree") == std::string::npos)
        throw UsageError("--embree-quality applies to --accel embree and embree-robust only");
    return quality;
}

bool uses_fastest_config(const ParsedArgs& args) {
    return !args.has("--accel") && !args.has("--packet") && !args.has("--builder");
}

int supported_packet(const Accel& accel, int packet) {
    for (int w : {16, 8, 4})
        if (w <= packet && accel.supports_packet(w)) return w;
    return 1;
}

int packet_width_from(const ParsedArgs& args, const Accel& accel) {
    const int width = int(args.integer("--packet", 1, 1, 16));
    if (width != 1 && width != 4 && width != 8 && width != 16)
        throw UsageError("--packet: expected 1, 4, 8 or 16, got " + std::to_string(width));
    if (!accel.supports_packet(width))
        throw UsageError("--packet " + std::to_string(width) + ": not available for " + accel.stats().name +
                         " in this build");
    return width;
}

struct ThreadLimit::Impl {
    tbb::global_control control;
};

ThreadLimit::ThreadLimit(int threads)
    : impl_(nullptr), threads_(threads > 0 ? threads : tbb::info::default_concurrency()) {
    if (threads > 0) impl_ = new Impl{tbb::global_control(tbb::global_control::max_allowed_parallelism, std::size_t(threads))};
}

ThreadLimit::~ThreadLimit() { delete impl_; }

}  // namespace raypack::app
