#pragma once
// `--heightfield-as triangles`: a scene's height fields as 2 (nx - 1)
// (ny - 1) triangles each, for comparing the direct walk with a mesh BVH.
#include "scene/scene.h"

namespace raypack {

/// The same scene with every height field replaced, in place in the
/// primitive order, by its cells' triangles (each cell cut along its
/// (i, j)-(i + 1, j + 1) diagonal), under the field's material. Where a
/// cell's patch is planar, the two triangles are that patch.
Scene height_fields_as_triangles(const Scene& scene);

}  // namespace raypack
