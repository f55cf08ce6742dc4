// raypack info SCENE
#include <cstdio>

#include "app/scene_options.h"
#include "app/commands.h"
#include "accel/prims/prim_kinds.h"
#include "scene/load.h"

namespace raypack::app {
namespace {

void print_vec(const char* label, const Vec3f& v) { std::printf("  %-10s %g %g %g\n", label, v.x, v.y, v.z); }

}  // namespace

int run_info(const Args& args) {
    const ParsedArgs p(args, scene_option_specs(), 1);
    if (p.help() || p.positional().empty()) {
        std::printf("usage: raypack info SCENE [--heightfield-as field|triangles] [--instances-as instances|flat]\n%s", scene_option_help().c_str());
        if (!p.help()) throw UsageError("missing SCENE");
        return 0;
    }
    const Scene scene = load_scene_from(p, p.positional()[0]);
    std::printf("scene: %s\n", scene.source.c_str());
    std::printf("primitives: %zu\n", scene.primitive_count());
    std::printf("  spheres    %zu\n  triangles  %zu\n  cones      %zu\n", scene.spheres.size(), scene.triangles.size(),
                scene.cones.size());
    if (!scene.height_fields.empty()) {
        std::size_t samples = 0, bytes = 0;
        for (const HeightField& h : scene.height_fields) samples += h.z.size(), bytes += h.bytes();
        std::printf("  height fields %zu (%zu samples, %.1f MiB with their min/max pyramids)\n",
                    scene.height_fields.size(), samples, double(bytes) / (1 << 20));
    }
    if (scene.placements()) {
        std::size_t stored = 0;
        for (const auto& o : scene.objects) stored += o->primitive_count() - o->instances.size();
        std::printf("  instances  %zu of %zu objects (%zu primitives stored in the objects)\n",
                    scene.instances.size() + scene.moving_instances.size(), scene.objects.size(), stored);
        if (!scene.moving_instances.empty())
            std::printf("  moving     %zu of them over the shutter [%g, %g]\n", scene.moving_instances.size(),
                        double(scene.shutter_open), double(scene.shutter_close));
        std::printf("primitives as instanced: %llu (with every instance expanded)\n",
                    static_cast<unsigned long long>(scene.instanced_primitive_count()));
    }
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
    if (c.lens_radius > 0) std::printf("  %-10s radius %g, focused at %g\n", "lens", c.lens_radius, c.focus_distance);
    std::printf("background: %g %g %g\n", scene.background.x, scene.background.y, scene.background.z);
    std::printf("lights: %zu\n", scene.light_count());
    auto colour = [](bool has, const Vec3f& v) {
        if (has) std::printf("  colour %g %g %g", v.x, v.y, v.z);
        std::printf("\n");
    };
    for (const auto& l : scene.lights) {
        std::printf("  point at %g %g %g", l.position.x, l.position.y, l.position.z);
        colour(l.has_color, l.color);
    }
    for (const auto& l : scene.area_lights) {
        if (l.shape == AreaLightShape::Sphere)
            std::printf("  sphere at %g %g %g radius %g", l.center.x, l.center.y, l.center.z, l.radius);
        else
            std::printf("  parallelogram at %g %g %g edges %g %g %g, %g %g %g", l.corner.x, l.corner.y, l.corner.z,
                        l.edge1.x, l.edge1.y, l.edge1.z, l.edge2.x, l.edge2.y, l.edge2.z);
        colour(l.has_color, l.color);
    }
    for (const auto& l : scene.distant_lights) {
        std::printf("  distant along %g %g %g", l.direction.x, l.direction.y, l.direction.z);
        colour(l.has_color, l.color);
    }
    std::printf("features:");
    for (const std::string& name : feature_names(scene.features)) std::printf(" %s", name.c_str());
    std::printf("\n");
    // What build_accel would choose with the default kernels (accel/prims/prim_kinds.h).
    std::printf("specialisation: %s (bvh4, bvh8 loops; the other structures run the general ones)\n",
                specialisation_name(specialisation_for(scene, KernelChoice{})));
    return 0;
}

}  // namespace raypack::app
