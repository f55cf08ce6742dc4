#pragma once
// --heightfield-as, shared by every command that loads a scene.
#include <string>

#include "app/commands.h"
#include "scene/scene.h"

namespace raypack::app {

/// --heightfield-as field|triangles
OptionSpec scene_option_spec();
/// The scene `spec` names, with its height fields as --heightfield-as says
/// (traced directly by default; `triangles`: 2 (nx - 1) (ny - 1) each).
Scene load_scene_from(const ParsedArgs& args, const std::string& spec);
std::string scene_option_help();

}  // namespace raypack::app
