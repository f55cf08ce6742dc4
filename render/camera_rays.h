#pragma once
// Primary rays from an NFF camera.
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

/// Orthonormal frame of the camera and the image-plane step per pixel at unit
/// distance. NFF's angle spans the centres of the top and bottom pixel rows,
/// so the step is 2 tan(angle / 2) / (height - 1); pixels are square.
struct CameraFrame {
    Vec3f origin;
    Vec3f forward, right, up;
    float step = 0;
    float tnear = 0;  ///< hither distance along the unit forward axis
    int width = 0, height = 0;
};

/// Right = forward x up, the usual right-handed frame (Tachyon and the common
/// NFF readers do the same). Throws std::invalid_argument for a degenerate view
/// (from == at, up parallel to the view direction, size <= 0).
CameraFrame make_camera_frame(const Camera& camera, int width, int height);

/// Ray through image position (px, py), with (0, 0) the top-left corner of the
/// image and (x + 0.5, y + 0.5) the centre of pixel (x, y). The direction's
/// component along `forward` is 1, so tnear = hither is the hither plane.
inline Rayf camera_ray(const CameraFrame& f, float px, float py) {
    const float sx = (px - 0.5f * float(f.width)) * f.step;
    const float sy = (0.5f * float(f.height) - py) * f.step;
    Rayf ray;
    ray.org = f.origin;
    ray.dir = f.forward + f.right * sx + f.up * sy;
    ray.tnear = f.tnear;
    return ray;
}

}  // namespace raypack
