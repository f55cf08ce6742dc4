#include "render/ray_sets.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "accel/accel.h"
#include "render/camera_rays.h"
#include "render/surface.h"

namespace raypack {

std::vector<Rayf> camera_ray_set(const Scene& scene, int width, int height) {
    const CameraFrame frame = make_camera_frame(scene.camera, width, height);
    std::vector<Rayf> rays;
    rays.reserve(std::size_t(width) * std::size_t(height));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) rays.push_back(camera_ray(frame, float(x) + 0.5f, float(y) + 0.5f));
    return rays;
}

std::vector<Rayf> shadow_ray_set(const Scene& scene, int width, int height) {
    if (scene.lights.empty()) return {};
    const std::vector<Rayf> camera = camera_ray_set(scene, width, height);
    const auto accel = build_accel(scene, AccelConfig{});
    std::vector<Hitf> hits(camera.size());
    tbb::parallel_for(std::size_t(0), camera.size(), std::size_t(1024), [&](std::size_t b) {
        const std::size_t n = std::min<std::size_t>(1024, camera.size() - b);
        accel->intersect({camera.data() + b, n}, {hits.data() + b, n});
    });
    const Vec3f light = scene.lights.front().position;
    std::vector<Rayf> rays;
    for (std::size_t i = 0; i < camera.size(); ++i) {
        if (!hits[i].found()) continue;
        const Surface s = surface_at(scene, camera[i], hits[i]);
        const Vec3f n = dot(s.geometric_normal, camera[i].dir) < 0 ? s.geometric_normal : -s.geometric_normal;
        const float scale = std::max({std::fabs(s.point.x), std::fabs(s.point.y), std::fabs(s.point.z), 1e-3f});
        Rayf r;
        r.org = s.point + n * (1e-4f * scale);
        r.dir = light - r.org;
        r.tnear = 0;
        r.tfar = 1.0f - 1e-6f;
        rays.push_back(r);
    }
    return rays;
}

}  // namespace raypack
