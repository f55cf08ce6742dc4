#include "render/camera_rays.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace raypack {

CameraFrame make_camera_frame(const Camera& camera, int width, int height) {
    if (width <= 0 || height <= 0) throw std::invalid_argument("image size must be positive");
    const Vec3f view = camera.at - camera.from;
    if (!(length(view) > 0)) throw std::invalid_argument("camera 'from' and 'at' coincide");
    CameraFrame f;
    f.origin = camera.from;
    f.forward = normalize(view);
    const Vec3f right = cross(f.forward, camera.up);
    if (!(length(right) > 1e-12f * length(camera.up))) throw std::invalid_argument("camera 'up' is parallel to the view direction");
    f.right = normalize(right);
    f.up = cross(f.right, f.forward);
    const double half = std::tan(double(camera.fov_deg) * std::numbers::pi / 360.0);
    f.step = float(2.0 * half / double(std::max(height - 1, 1)));
    f.tnear = camera.hither;
    f.width = width;
    f.height = height;
    return f;
}

}  // namespace raypack
