#pragma once
// The recursive Whitted tracer raypack used before the wavefront renderer,
// for tests only: the reference the new renderer matches bit for bit.
#include "accel/accel.h"
#include "render/image.h"
#include "render/whitted.h"
#include "scene/scene.h"

namespace raypack::reference {

/// One ray per pixel centre, one ray at a time, recursively; single thread.
Image render_whitted_recursive(const Scene& scene, const Accel& accel, const WhittedOptions& options,
                               RenderStats& stats);

}  // namespace raypack::reference
