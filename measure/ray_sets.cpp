#include "measure/ray_sets.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "accel/accel.h"
#include "render/camera_rays.h"
#include "render/light_sampling.h"
#include "render/ray_offset.h"
#include "render/sampling.h"
#include "render/surface.h"
#include "render/tiles.h"

namespace raypack {
namespace {

/// The scene time of pixel i's rays when the scene moves (with a caller
/// asking for times), else -inf (none: the shutter's opening).
std::vector<float> pixel_times(const Scene& scene, std::size_t pixels, const std::vector<float>* wanted) {
    if (wanted == nullptr || scene.moving_instances.empty()) return std::vector<float>(pixels, -INFINITY);
    std::vector<float> times(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
        std::uint64_t state = 0x243F6A8885A308D3ull ^ std::uint64_t(i);
        splitmix64(state);
        const float u = uniform01(state);
        times[i] = (1.0f - u) * scene.shutter_open + u * scene.shutter_close;
    }
    return times;
}

/// The closest hit of every camera ray at its time, found with the reference BVH2.
std::vector<Hitf> camera_hits(const Scene& scene, const std::vector<Rayf>& camera, const std::vector<float>& times) {
    const auto accel = build_accel(scene, AccelConfig{});
    std::vector<Hitf> hits(camera.size());
    tbb::parallel_for(std::size_t(0), camera.size(), std::size_t(1024), [&](std::size_t b) {
        const std::size_t n = std::min<std::size_t>(1024, camera.size() - b);
        accel->intersect_at(1, {camera.data() + b, n}, {times.data() + b, n}, {hits.data() + b, n});
    });
    return hits;
}

/// The hit point of `ray` moved off the surface by `offset`, to the side the
/// ray came from, so that the new ray does not hit the same surface again.
Vec3f offset_origin(const Scene& scene, const RayOffset& offset, const Rayf& ray, const Hitf& hit,
                    const Surface& s, float time) {
    const Vec3f n = dot(s.geometric_normal, ray.dir) < 0 ? s.geometric_normal : -s.geometric_normal;
    return offset.offset(offset.hit_point(scene, ray, hit, s.point, time), n);
}

}  // namespace

std::vector<Rayf> camera_ray_set(const Scene& scene, int width, int height, std::vector<float>* times,
                                 PixelOrder order) {
    if (times != nullptr) {
        times->clear();
        if (!scene.moving_instances.empty())
            *times = pixel_times(scene, std::size_t(width) * std::size_t(height), times);
    }
    const CameraFrame frame = make_camera_frame(scene.camera, width, height);
    std::vector<Rayf> rays;
    rays.reserve(std::size_t(width) * std::size_t(height));
    if (order == PixelOrder::Rows) {
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) rays.push_back(camera_ray(frame, float(x) + 0.5f, float(y) + 0.5f));
        return rays;
    }
    const TileGrid tiles{width, height, 8};
    std::vector<PixelXY> pixels;
    for (int t = 0; t < tiles.count(); ++t) {
        tiles.pixels(t, pixels);
        for (const PixelXY& p : pixels) rays.push_back(camera_ray(frame, float(p.x) + 0.5f, float(p.y) + 0.5f));
    }
    return rays;
}

std::vector<Rayf> shadow_ray_set(const Scene& scene, int width, int height, OffsetPolicy policy,
                                 std::vector<float>* times, PixelOrder order) {
    if (times != nullptr) times->clear();
    // The first light: a point light, else a distant one, else an area light.
    const bool point = !scene.lights.empty(), distant = !point && !scene.distant_lights.empty();
    if (!point && !distant && scene.area_lights.empty()) return {};
    const std::vector<Rayf> camera = camera_ray_set(scene, width, height, nullptr, order);
    const std::vector<float> when = pixel_times(scene, camera.size(), times);
    const std::vector<Hitf> hits = camera_hits(scene, camera, when);
    const RayOffset offset(policy, scene);
    std::vector<Rayf> rays;
    for (std::size_t i = 0; i < camera.size(); ++i) {
        if (!hits[i].found()) continue;
        const Vec3f org = offset_origin(scene, offset, camera[i], hits[i],
                                        surface_at(scene, camera[i], hits[i], when[i]), when[i]);
        if (times != nullptr && !scene.moving_instances.empty()) times->push_back(when[i]);
        Rayf& r = rays.emplace_back();
        if (point) {
            spawn_ray_to(org, scene.lights.front().position, offset, r);
        } else if (distant) {
            spawn_ray(org, -scene.distant_lights.front().direction, offset, r);
        } else {
            // Whitted's area-light sample: a parallelogram's centre, a
            // sphere's point facing the surface (render/light_sampling.h).
            const AreaLight& l = scene.area_lights.front();
            const Sample2 u = l.shape == AreaLightShape::Sphere ? Sample2{0.0f, 0.0f} : Sample2{0.5f, 0.5f};
            spawn_ray_to(org, sample_area_light(l, org, u).point, offset, r);
        }
    }
    return rays;
}

std::vector<Rayf> diffuse_ray_set(const Scene& scene, int width, int height, std::uint64_t seed, OffsetPolicy policy,
                                  std::vector<float>* times, PixelOrder order) {
    if (times != nullptr) times->clear();
    const std::vector<Rayf> camera = camera_ray_set(scene, width, height, nullptr, order);
    const std::vector<float> when = pixel_times(scene, camera.size(), times);
    const RayOffset offset(policy, scene);
    const std::vector<Hitf> hits = camera_hits(scene, camera, when);
    std::vector<Rayf> rays;
    for (std::size_t i = 0; i < camera.size(); ++i) {
        if (!hits[i].found()) continue;
        const Surface s = surface_at(scene, camera[i], hits[i], when[i]);
        if (times != nullptr && !scene.moving_instances.empty()) times->push_back(when[i]);
        const Vec3f n = dot(s.shading_normal, camera[i].dir) < 0 ? s.shading_normal : -s.shading_normal;
        std::uint64_t state = seed * 0x9E3779B97F4A7C15ull ^ std::uint64_t(i);
        splitmix64(state);  // decorrelate neighbouring pixels before the first draw
        const float u1 = uniform01(state), u2 = uniform01(state);
        Rayf r;
        r.org = offset_origin(scene, offset, camera[i], hits[i], s, when[i]);
        r.dir = OrthonormalBasis(n).to_world(cosine_hemisphere(u1, u2));
        r.tnear = offset.tnear();
        rays.push_back(r);
    }
    return rays;
}

}  // namespace raypack
