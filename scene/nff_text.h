#pragma once
// Private to the loaders: NFF parsing straight from text already in memory, so
// that generated scenes are not copied into a stream first.
#include <string>
#include <string_view>

#include "scene/scene.h"

namespace raypack {

/// Throws SceneError naming `name`.
Scene load_nff_text(std::string_view text, const std::string& name);

}  // namespace raypack
