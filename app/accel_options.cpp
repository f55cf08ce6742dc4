#include "app/accel_options.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "accel/bvh/bvh_builders.h"

namespace raypack::app {

std::vector<OptionSpec> accel_option_specs() {
    return {{"--accel", "", 1}, {"--sphere", "", 1}, {"--triangle", "", 1}, {"--packet", "", 1}, {"--builder", "", 1}};
}

std::string accel_options_help() {
    return "  With none of --accel, --builder, --packet: the fastest measured configuration for the rays\n"
           "  (camera: bvh4 --packet 16, shadow: bvh8 --packet 16, diffuse: bvh4 --packet 16; README)\n"
           "  --accel " + accel_kinds_list() + "  acceleration structure (default bvh2)\n"
           "  --builder " + bvh_builder_list() + "  BVH builder for bvh2|bvh4|bvh8 (default binned):\n"
           "                binned SAH, full-sweep SAH, Morton/LBVH, spatial splits (SBVH)\n"
           "  --sphere geometric|algebraic|precise     ray-sphere test (default geometric)\n"
           "  --triangle moeller|watertight|plane     ray-triangle test (default moeller)\n"
           "  --packet 1|4|8|16             rays per packet (default 1; 16 needs AVX-512)\n";
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
    const std::string sphere = args.text("--sphere", "geometric");
    if (sphere == "geometric") config.kernels.sphere = SphereMethod::Geometric;
    else if (sphere == "algebraic") config.kernels.sphere = SphereMethod::Algebraic;
    else if (sphere == "precise") config.kernels.sphere = SphereMethod::Precise;
    else throw UsageError("--sphere: expected geometric, algebraic or precise, got '" + sphere + "'");
    const std::string tri = args.text("--triangle", "moeller");
    if (tri == "moeller") config.kernels.triangle = TriangleMethod::Moeller;
    else if (tri == "plane") config.kernels.triangle = TriangleMethod::Plane;
    else if (tri == "watertight") config.kernels.triangle = TriangleMethod::Watertight;
    else throw UsageError("--triangle: expected moeller, watertight or plane, got '" + tri + "'");
    return config;
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
