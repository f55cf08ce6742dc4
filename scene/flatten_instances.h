#pragma once
// A scene with instances as the scene it stands for: every placement's
// primitives transformed and copied in (`--instances-as flat`), to measure
// instancing against and to test it by.
#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace raypack {

/// The scene with each instance replaced, in place, by its object's
/// primitives under its transform (nested instances likewise). Spheres and
/// cones need transforms that keep their shape (a rotation, a uniform scale
/// and a translation), height fields an axis-aligned positive scale; other
/// cases throw SceneError. If `hit_ids` is given, (*hit_ids)[p] is the hit id
/// the instanced scene reports for the flat scene's primitive p.
Scene flatten_instances(const Scene& scene, std::vector<std::uint32_t>* hit_ids = nullptr);

}  // namespace raypack
