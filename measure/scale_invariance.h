#pragma once
// Does a render depend on where the scene sits and how large it is? The same
// scene scaled by s and moved by t should give the same picture; an offset
// policy with absolute constants does not (issue 19: Waechter & Binder's
// published 1/32 and 1/65536 at scale 1e-4). The trade bench and the tests
// measure it for every offset policy.
#include "measure/accuracy_measures.h"
#include "render/ray_offset.h"
#include "scene/scene.h"

namespace raypack {

/// `scene` with every position (primitives, lights, camera) mapped to
/// p * scale + translation and every length (radii, hither) to length * scale;
/// directions and shading stay as they are. `scale` > 0.
Scene transformed_scene(const Scene& scene, float scale, const Vec3f& translation);

/// The Whitted render (offset `policy`, default structure) of `scene`
/// transformed by (scale, translation) against the render of `scene` itself.
ImageError scale_invariance_error(const Scene& scene, OffsetPolicy policy, float scale, const Vec3f& translation,
                                  int width, int height);

}  // namespace raypack
