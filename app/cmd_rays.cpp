// raypack rays SCENE --kind camera|shadow|diffuse [--res W H] [--order tiles|rows] [--seed S] [--offset POLICY] -o FILE.rays
// Writes the ray sets the benchmarks and the Embree comparison trace.
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "app/scene_options.h"
#include "app/commands.h"
#include "app/variant_options.h"
#include "render/camera_rays.h"
#include "measure/ray_sets.h"
#include "scene/load.h"
#include "scene/ray_file.h"

namespace raypack::app {

int run_rays(const Args& args) {
    std::vector<OptionSpec> spec = {{"--kind", "", 1}, {"--res", "", 2}, {"--output", "-o", 1}, {"--seed", "", 1},
                                    {"--order", "", 1}, offset_option_spec()};
    for (OptionSpec& k : scene_option_specs()) spec.push_back(std::move(k));
    const ParsedArgs p(args, spec, 1);
    if (p.help() || p.positional().empty()) {
        std::printf(
            "usage: raypack rays SCENE --kind camera|shadow|diffuse [--res W H] [--order tiles|rows] [--seed S]\n"
            "                   [--offset POLICY] -o FILE.rays\n"
            "  camera   one closest-hit ray through each pixel centre (kind 0)\n"
            "  shadow   any-hit rays from each camera hit to the first light (kind 1): a point light,\n"
            "           else a distant one, else an area light's centre (a sphere's facing point)\n"
            "  diffuse  a cosine-weighted bounce from each camera hit (kind 0); --seed S (default 1)\n"
            "--order tiles (the default): pixels in tiles of 8 x 8, each in 4 x 4 blocks, so that every 8 or 16\n"
            "consecutive rays cover a 4 x 2 or 4 x 4 patch of the image, as a renderer's packets do; rows: row by\n"
            "row from the top. Shadow and diffuse rays follow their pixels' order.\n"
            "A scene that moves (shutter, move) gives each pixel's rays a time over the shutter\n"
            "(a version 2 file, docs/rays.md).\n"
            "%s",
            (offset_option_help() + scene_option_help()).c_str());
        if (!p.help()) throw UsageError("missing SCENE");
        return 0;
    }
    if (!p.has("--output")) throw UsageError("missing -o FILE.rays");
    const std::string kind = p.text("--kind", "camera");
    const OffsetPolicy offset = offset_policy_from(p);
    const std::string order_name = p.text("--order", "tiles");
    if (order_name != "tiles" && order_name != "rows")
        throw UsageError("--order: expected tiles or rows, got '" + order_name + "'");
    const PixelOrder order = order_name == "tiles" ? PixelOrder::Tiles : PixelOrder::Rows;
    const Scene scene = load_scene_from(p, p.positional()[0]);
    const int w = int(p.integer("--res", scene.camera.width, 1, 16384, 0));
    const int h = int(p.integer("--res", scene.camera.height, 1, 16384, 1));
    std::vector<Rayf> rays;
    std::vector<float> times;  // a scene that moves: one per ray (a version 2 file)
    RayKind file_kind = RayKind::ClosestHit;
    if (kind == "camera") {
        rays = camera_ray_set(scene, w, h, &times, order);
    } else if (kind == "shadow") {
        rays = shadow_ray_set(scene, w, h, offset, &times, order);
        file_kind = RayKind::AnyHit;
    } else if (kind == "diffuse") {
        rays = diffuse_ray_set(scene, w, h, std::uint64_t(p.integer("--seed", 1, 0, 1LL << 62)), offset, &times, order);
    } else {
        throw UsageError("--kind: expected camera, shadow or diffuse, got '" + kind + "'");
    }
    // The readers refuse what they cannot trace; so does the writer, rather
    // than leave a file no tracer reads (coordinates near the float range
    // give offsets and directions that overflow).
    for (std::size_t i = 0; i < rays.size(); ++i)
        if (!all_finite(rays[i].org) || !all_finite(rays[i].dir) || std::isnan(rays[i].tnear) || std::isnan(rays[i].tfar))
            throw std::runtime_error(p.positional()[0] + ": " + kind + " ray " + std::to_string(i) +
                                     " is not finite (the scene's coordinates overflow float); nothing written");
    write_rays(p.text("--output"), file_kind, rays, times);
    std::printf("wrote %zu %s rays%s to %s\n", rays.size(), kind.c_str(),
                times.empty() ? "" : " (with times over the shutter)", p.text("--output").c_str());
    return 0;
}

}  // namespace raypack::app
