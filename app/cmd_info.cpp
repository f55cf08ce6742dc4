// raypack info SCENE
#include <cstdio>

#include "app/commands.h"
#include "scene/load.h"

namespace raypack::app {
namespace {

void print_vec(const char* label, const Vec3f& v) { std::printf("  %-10s %g %g %g\n", label, v.x, v.y, v.z); }

}  // namespace

int run_info(const Args& args) {
    const ParsedArgs p(args, {}, 1);
    if (p.help() || p.positional().empty()) {
        std::printf("usage: raypack info SCENE\n");
        if (!p.help()) throw UsageError("missing SCENE");
        return 0;
    }
    const Scene scene = load_scene(p.positional()[0]);
    std::printf("scene: %s\n", scene.source.c_str());
    std::printf("primitives: %zu\n", scene.primitive_count());
    std::printf("  spheres    %zu\n  triangles  %zu\n  cones      %zu\n", scene.spheres.size(), scene.triangles.size(),
                scene.cones.size());
    std::printf("materials: %zu\n", scene.materials.size());
    const Box3f b = scene_bounds(scene);
    std::printf("bounds:\n");
    print_vec("min", b.lo);
    print_vec("max", b.hi);
    const Camera& c = scene.camera;
    std::printf("camera:%s\n", scene.has_camera ? "" : " (none in file; defaults)");
    print_vec("from", c.from);
    print_vec("at", c.at);
    print_vec("up", c.up);
    std::printf("  %-10s %g\n  %-10s %g\n  %-10s %d %d\n", "angle", c.fov_deg, "hither", c.hither, "resolution", c.width,
                c.height);
    std::printf("background: %g %g %g\n", scene.background.x, scene.background.y, scene.background.z);
    std::printf("lights: %zu\n", scene.lights.size());
    for (const auto& l : scene.lights) {
        std::printf("  at %g %g %g", l.position.x, l.position.y, l.position.z);
        if (l.has_color) std::printf("  colour %g %g %g", l.color.x, l.color.y, l.color.z);
        std::printf("\n");
    }
    const Features& f = scene.features;
    std::printf("features:");
    const std::pair<bool, const char*> names[] = {{f.spheres, "spheres"},
                                                  {f.triangles, "triangles"},
                                                  {f.cones, "cones"},
                                                  {f.vertex_normals, "vertex-normals"},
                                                  {f.reflection, "reflection"},
                                                  {f.transmission, "transmission"},
                                                  {f.colored_lights, "coloured-lights"},
                                                  {f.inside_only, "inside-only"}};
    for (const auto& [on, name] : names)
        if (on) std::printf(" %s", name);
    std::printf("\n");
    return 0;
}

}  // namespace raypack::app
