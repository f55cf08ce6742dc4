// The recursive, one-ray-at-a-time Whitted tracer that raypack rendered
// with until the wavefront renderer replaced it (render/whitted.cpp before
// the change), kept verbatim as the reference the new renderer must match
// bit for bit (tests/test_render_identity.cpp).
#include "tests/reference_whitted.h"

#include <cmath>

#include "render/camera_rays.h"
#include "render/phong_power.h"
#include "render/surface.h"

namespace raypack::reference {
namespace {

class WhittedTracer {
public:
    WhittedTracer(const Scene& scene, const Accel& accel, const WhittedOptions& options)
        : scene_(scene), accel_(accel), options_(options), offset_(options.offset, scene) {
        // SPD Readme: each light and the ambient term get sqrt(L) / (2 L).
        const float n = float(std::max<std::size_t>(scene.lights.size(), 1));
        intensity_ = std::sqrt(n) / (2.0f * n);
    }

    Vec3f trace(const Rayf& ray, int depth, RenderStats& stats) const {
        return shade_hit(ray, accel_.intersect1(ray), depth, stats);
    }

    /// Colour along `ray` whose closest hit is already known.
    Vec3f shade_hit(const Rayf& ray, const Hitf& hit, int depth, RenderStats& stats) const {
        if (depth == 1) {
            ++stats.eye_rays;
            stats.eye_hits += hit.found();
        }
        if (!hit.found()) return scene_.background;
        return shade(ray, hit, depth, stats);
    }

private:
    const Scene& scene_;
    const Accel& accel_;
    const WhittedOptions& options_;
    RayOffset offset_;
    float intensity_ = 1;

    Vec3f shade(const Rayf& ray, const Hitf& hit, int depth, RenderStats& stats) const {
        const Surface s = surface_at(scene_, ray, hit);
        const Material& m = scene_.materials[s.material];
        const Vec3f view = normalize(ray.dir);
        // Shade the side the ray arrives on: both normals face the viewer.
        const bool front = dot(view, s.geometric_normal) < 0;
        const Vec3f ng = front ? s.geometric_normal : -s.geometric_normal;
        Vec3f ns = front ? s.shading_normal : -s.shading_normal;
        if (dot(ns, ng) < 0) ns = ng;  // interpolated normal bent past the surface
        const Vec3f p = offset_.hit_point(scene_, ray, hit, s.point);
        const Vec3f above = offset_.offset(p, ng);

        Vec3f color = m.color * (intensity_ * m.kd);  // ambient
        for (const PointLight& light : scene_.lights) {
            const Vec3f to_light = light.position - above;
            const float dist = length(to_light);
            const Vec3f l = to_light / dist;
            // SPD protocol: no shadow ray when the surface faces away from the light.
            if (dot(ns, l) <= 0 || dot(ng, l) <= 0) continue;
            ++stats.shadow_rays;
            Rayf shadow;
            shadow.org = above;
            shadow.dir = to_light;
            shadow.tnear = offset_.tnear();
            shadow.tfar = 1.0f - 1e-6f;
            if (accel_.occluded1(shadow)) continue;
            const float atten =
                1.0f / (options_.atten_c2 * dist * dist + options_.atten_c1 * dist + options_.atten_c0);
            const Vec3f light_color = light.color * (intensity_ * atten);
            const float diffuse = m.kd * dot(ns, l);
            const Vec3f r = ns * (2.0f * dot(ns, l)) - l;  // mirror of l about the normal
            const float rv = std::max(0.0f, -dot(r, view));
            const float specular = m.ks > 0 && rv > 0 ? m.ks * phong_power(rv, m.shine) : 0.0f;
            color += light_color * m.color * diffuse + light_color * specular;
        }
        if (depth >= options_.max_depth) return color;

        // SPD protocol (Readme, items 8 and 9): reflective and transmitting
        // surfaces both spawn a reflection ray, weighted by Ks; transmitters
        // also spawn a refraction ray unless total internal reflection occurs,
        // in which case the reflection carries the transmitted share as well.
        const Vec3f reflected_dir = view - ns * (2.0f * dot(view, ns));
        Vec3f reflected{};
        if (m.ks > 0 || m.transmittance > 0) {
            ++stats.reflect_rays;
            reflected = trace(secondary(above, reflected_dir), depth + 1, stats);
            color += reflected * m.ks;
        }
        if (m.transmittance > 0) {
            // Snell's law; entering when the ray meets the outward side.
            const float eta = front ? 1.0f / m.ior : m.ior;
            const float cos_i = -dot(view, ns);
            const float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
            if (k >= 0) {
                ++stats.refract_rays;
                const Vec3f dir = view * eta + ns * (eta * cos_i - std::sqrt(k));
                color += trace(secondary(offset_.offset(p, -ng), dir), depth + 1, stats) * m.transmittance;
            } else {
                color += reflected * m.transmittance;
            }
        }
        return color;
    }

    Rayf secondary(const Vec3f& org, const Vec3f& dir) const {
        Rayf r;
        r.org = org;
        r.dir = dir;
        r.tnear = offset_.tnear();
        return r;
    }
};

}  // namespace

Image render_whitted_recursive(const Scene& scene, const Accel& accel, const WhittedOptions& options,
                               RenderStats& stats) {
    Image image(options.width, options.height);
    const CameraFrame frame = make_camera_frame(scene.camera, options.width, options.height);
    const WhittedTracer tracer(scene, accel, options);
    for (int y = 0; y < options.height; ++y)
        for (int x = 0; x < options.width; ++x)
            image.set(x, y, tracer.trace(camera_ray(frame, float(x) + 0.5f, float(y) + 0.5f), 1, stats));
    return image;
}

}  // namespace raypack::reference
