#include "app/scene_options.h"

#include <utility>

#include "scene/flatten_instances.h"
#include "scene/height_field_mesh.h"
#include "scene/load.h"

namespace raypack::app {

std::vector<OptionSpec> scene_option_specs() { return {{"--heightfield-as", "", 1}, {"--instances-as", "", 1}}; }

Scene load_scene_from(const ParsedArgs& args, const std::string& spec) {
    const std::string as = args.has("--heightfield-as") ? args.text("--heightfield-as") : "field";
    if (as != "field" && as != "triangles")
        throw UsageError("--heightfield-as: expected field or triangles, got '" + as + "'");
    const std::string inst = args.has("--instances-as") ? args.text("--instances-as") : "instances";
    if (inst != "instances" && inst != "flat")
        throw UsageError("--instances-as: expected instances or flat, got '" + inst + "'");
    Scene scene = load_scene(spec);
    if (as == "triangles") scene = height_fields_as_triangles(scene);
    if (inst == "flat") scene = flatten_instances(scene);
    return scene;
}

std::string scene_option_help() {
    return "  --heightfield-as field|triangles  height fields traced directly (default), or loaded as\n"
           "                 2 (nx-1)(ny-1) triangles each, for comparison\n"
           "  --instances-as instances|flat  instances traced through their objects' structures\n"
           "                 (default), or every placement copied into the scene, for comparison\n";
}

std::vector<std::string> feature_names(const Features& f) {
    const std::pair<bool, const char*> names[] = {{f.spheres, "spheres"},
                                                  {f.triangles, "triangles"},
                                                  {f.cones, "cones"},
                                                  {f.height_fields, "height-fields"},
                                                  {f.instances, "instances"},
                                                  {f.motion, "motion"},
                                                  {f.vertex_normals, "vertex-normals"},
                                                  {f.reflection, "reflection"},
                                                  {f.transmission, "transmission"},
                                                  {f.colored_lights, "coloured-lights"},
                                                  {f.inside_only, "inside-only"},
                                                  {f.area_lights, "area-lights"},
                                                  {f.distant_lights, "distant-lights"},
                                                  {f.glossy, "glossy"},
                                                  {f.thin_lens, "thin-lens"}};
    std::vector<std::string> out;
    for (const auto& [on, name] : names)
        if (on) out.emplace_back(name);
    return out;
}

}  // namespace raypack::app
