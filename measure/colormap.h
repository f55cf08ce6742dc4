#pragma once
// A perceptually uniform colour map for false-colour images.
#include "kernels/vec3.h"

namespace raypack {

/// Matplotlib's viridis (van der Walt & Smith, 2015) at t in [0, 1] (clamped),
/// as sRGB-encoded values ready for an 8-bit image.
Vec3f viridis(float t);

}  // namespace raypack
