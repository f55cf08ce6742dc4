#pragma once
// Camera rays through a thin lens (Cook, Porter, Carpenter, "Distributed Ray
// Tracing", SIGGRAPH 1984; Kolb, Mitchell, Hanrahan 1995): every ray of an
// image position passes through the point that the pinhole ray reaches on
// the plane in focus, and starts from a point of the aperture disc.
#include "render/camera_rays.h"
#include "render/film.h"
#include "render/sampler.h"
#include "render/sampling.h"

namespace raypack {

/// The ray of image position (px, py) through lens point `lens` (a point of
/// the unit square, mapped concentrically onto the aperture of radius
/// `radius`), focused at distance `focus` along the view axis. As with
/// camera_ray, the direction's component along `forward` is 1, so tnear is
/// still the hither plane. radius 0 gives camera_ray's ray exactly.
inline Rayf thin_lens_ray(const CameraFrame& f, float px, float py, Sample2 lens, float radius, float focus) {
    Rayf ray = camera_ray(f, px, py);
    if (radius <= 0) return ray;
    const Vec3f d = concentric_disk(lens.x, lens.y);
    const Vec3f offset = f.right * (radius * d.x) + f.up * (radius * d.y);
    // The pinhole ray reaches the focus plane at org + dir * focus; the lens
    // ray aims there from org + offset, scaled back to unit forward length.
    ray.org = ray.org + offset;
    ray.dir = ray.dir - offset / focus;
    return ray;
}

/// The camera ray of pixel (x, y) for the unit-square points `position`
/// (sampler dimension 0, through the pixel filter) and `lens` (dimension 1;
/// unused by a pinhole).
inline Rayf camera_ray_of_sample(const CameraFrame& f, const Camera& camera, PixelFilter filter, Sample2 position,
                                 Sample2 lens, int x, int y) {
    const Sample2 off = filter_offset(filter, position);
    return thin_lens_ray(f, float(x) + 0.5f + off.x, float(y) + 0.5f + off.y, lens, camera.lens_radius,
                         camera.focus_distance);
}

}  // namespace raypack
