#include "measure/scale_invariance.h"

#include "accel/accel.h"
#include "render/whitted.h"

namespace raypack {
namespace {

Image render(const Scene& scene, OffsetPolicy policy, int width, int height) {
    WhittedOptions options;
    options.width = width;
    options.height = height;
    options.offset = policy;
    const auto accel = build_accel(scene, AccelConfig{});
    Image image(width, height);
    render_whitted(scene, *accel, options, image);
    return image;
}

}  // namespace

Scene transformed_scene(const Scene& scene, float scale, const Vec3f& translation) {
    Scene out = scene;
    const auto place = [&](Vec3f& p) { p = p * scale + translation; };
    place(out.camera.from);
    place(out.camera.at);
    out.camera.hither *= scale;
    out.camera.lens_radius *= scale;
    out.camera.focus_distance *= scale;
    for (PointLight& l : out.lights) place(l.position);
    for (AreaLight& l : out.area_lights) {
        place(l.corner);
        place(l.center);
        l.edge1 = l.edge1 * scale;
        l.edge2 = l.edge2 * scale;
        l.radius *= scale;
    }
    for (Vec3f& c : out.spheres.center) place(c);
    for (float& r : out.spheres.radius) r *= scale;
    for (auto* v : {&out.triangles.p0, &out.triangles.p1, &out.triangles.p2})
        for (Vec3f& p : *v) place(p);
    for (auto* v : {&out.cones.base, &out.cones.apex})
        for (Vec3f& p : *v) place(p);
    for (auto* v : {&out.cones.base_radius, &out.cones.apex_radius})
        for (float& r : *v) r *= scale;
    return out;
}

ImageError scale_invariance_error(const Scene& scene, OffsetPolicy policy, float scale, const Vec3f& translation,
                                  int width, int height) {
    const Image reference = render(scene, policy, width, height);
    const Image moved = render(transformed_scene(scene, scale, translation), policy, width, height);
    return image_error(moved, reference);
}

}  // namespace raypack
