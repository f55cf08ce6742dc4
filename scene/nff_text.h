#pragma once
// Private to the loaders: NFF and OBJ parsing straight from text already in
// memory, so that generated scenes are not copied into a stream first and the
// fuzz targets need no file.
#include <cstdint>
#include <string>
#include <string_view>

#include "scene/scene.h"

namespace raypack {

/// Throws SceneError naming `name`.
Scene load_nff_text(std::string_view text, const std::string& name);

/// The faces of OBJ file `path` as triangles of `material`, appended to
/// `scene` (NFF's `obj` line and load_obj_file). Throws SceneError naming `path`.
void append_obj_triangles(const std::string& path, std::uint32_t material, Scene& scene);
/// The same on OBJ text already in memory; errors name `name`.
void append_obj_text(std::string_view text, const std::string& name, std::uint32_t material, Scene& scene);

/// load_obj_file on OBJ text already in memory (the fuzz target's entry).
Scene load_obj_text(std::string_view text, const std::string& name);

}  // namespace raypack
