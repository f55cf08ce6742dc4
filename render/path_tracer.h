#pragma once
// Monte Carlo path tracing (Kajiya, "The Rendering Equation", SIGGRAPH
// 1986) with next-event estimation and Russian roulette, traced as a
// wavefront: per tile, the vertices of one bounce of every path are one
// batch through the structure's packet queries, and so are their shadow
// rays.
//
// Radiometry: unlike the Whitted and distribution integrators, which follow
// the SPD's non-physical intensity rule, paths carry radiance. An NFF fill
// `f` is a Lambertian albedo color * Kd, a specular weight Ks (a mirror, or
// with `gloss n` a normalised Phong lobe) and a transmitted weight T (Snell,
// index of refraction); one of the three is chosen per bounce in proportion
// to its weight. An area light's surface emits its colour as radiance from
// its emitting side, a point light of colour c has radiant intensity c, a
// distant light gives irradiance c on a surface facing it (docs/renderer.md).
#include "accel/accel.h"
#include "render/image.h"
#include "render/whitted.h"
#include "scene/scene.h"

namespace raypack {

struct PathOptions {
    /// Bounces after which Russian roulette may end a path (0: from the first).
    int rr_depth = 3;
    /// Hard cap on path vertices after the camera (the eye ray's hit is 1).
    int max_depth = 64;
    /// Diffuse vertices of static scenes shaded in SIMD lanes (the same bits
    /// as one by one); false: one by one, the reference the lanes are
    /// tested against.
    bool lanes = true;
    /// Rays that could carry no light are not traced: with no area light
    /// and a black background, a ray from the last vertex that may light
    /// its path (max_depth - 1) can only find a surface whose lighting is
    /// never computed, so it is not spawned (the image is the same bit for
    /// bit). false: traced anyway, the reference this is tested against.
    bool skip_dark_rays = true;
};

/// Renders `options.spp` paths per pixel (options.distribution is implied:
/// sampler, seed, filter, lens and the tile size are read from `options`).
RenderStats render_path(const Scene& scene, const Accel& accel, const WhittedOptions& options,
                        const PathOptions& path, Image& image);

}  // namespace raypack
