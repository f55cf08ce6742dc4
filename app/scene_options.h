#pragma once
// --heightfield-as and --instances-as, shared by every command that loads a scene.
#include <string>
#include <vector>

#include "app/commands.h"
#include "scene/scene.h"

namespace raypack::app {

/// --heightfield-as field|triangles, --instances-as instances|flat
std::vector<OptionSpec> scene_option_specs();
/// The scene `spec` names, with its height fields as --heightfield-as says
/// (traced directly by default; `triangles`: 2 (nx - 1) (ny - 1) each) and
/// its instances as --instances-as says (two levels by default; `flat`:
/// every placement's primitives copied into the scene).
Scene load_scene_from(const ParsedArgs& args, const std::string& spec);
std::string scene_option_help();
/// The names of the features a scene uses ("spheres", "instances", ...).
std::vector<std::string> feature_names(const Features& f);

}  // namespace raypack::app
