// Samples per pixel against image error, per sampler: renders a scene with
// the distribution integrator at 1, 4, 16, 64 and 256 samples per pixel with
// each sampler and prints the RMS error against a long reference render
// (4096 samples, Sobol', another seed) and the render time, as a Markdown
// table (docs/renderer.md). Times are single runs on one thread: compare
// them within one table only.
//
// usage: raypack_sampler_error [SCENE] [RES]   (default gen:cornell:1, 64)
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "accel/accel.h"
#include "render/whitted.h"
#include "scene/load.h"

using namespace raypack;

namespace {

double rms_error(const Image& a, const Image& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) sum += (double(a.rgb[i]) - b.rgb[i]) * (double(a.rgb[i]) - b.rgb[i]);
    return std::sqrt(sum / double(a.rgb.size()));
}

}  // namespace

int main(int argc, char** argv) {
    const std::string spec = argc > 1 ? argv[1] : "gen:cornell:1";
    const int res = argc > 2 ? std::atoi(argv[2]) : 64;
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    const Scene scene = load_scene(spec);
    const auto accel = build_accel(scene, accel_config("bvh4"));
    WhittedOptions o;
    o.width = o.height = res;
    o.distribution = true;
    o.packet = o.secondary_packet = accel->supports_packet(16) ? 16 : 1;
    o.light_samples = 1;
    Image reference;
    o.spp = 4096;
    o.sampler = SamplerKind::Sobol;
    o.seed = 12345;
    render_whitted(scene, *accel, o, reference);
    std::printf("# %s, %d x %d, distribution integrator, 1 light sample, box filter, 1 thread;\n"
                "# RMS error against 4096 Sobol' samples (seed 12345), time of one render in ms\n",
                spec.c_str(), res, res);
    std::printf("| spp | random | stratified | sobol | regular |\n|---|---|---|---|---|\n");
    for (int spp : {1, 4, 16, 64, 256}) {
        std::printf("| %d |", spp);
        for (SamplerKind k : {SamplerKind::Random, SamplerKind::Stratified, SamplerKind::Sobol, SamplerKind::Regular}) {
            o.spp = spp;
            o.sampler = k;
            o.seed = 1;
            Image image;
            const RenderStats st = render_whitted(scene, *accel, o, image);
            std::printf(" %.5f (%.0f ms) |", rms_error(image, reference), st.render_ms);
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    return 0;
}
