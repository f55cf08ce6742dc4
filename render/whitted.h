#pragma once
// Whitted ray tracing (Whitted, "An Improved Illumination Model for Shaded
// Display", CACM 1980) with NFF's shading parameters, and its distributed
// form (Cook, Porter, Carpenter, "Distributed Ray Tracing", SIGGRAPH 1984:
// samples over the pixel, the lens, area lights and glossy lobes), traced as
// a wavefront: per tile, every ray of one depth is a batch through the
// structure's packet queries, and the recursion of the model becomes
// iteration over depth.
#include <cstdint>
#include <span>

#include "accel/accel.h"
#include "render/film.h"
#include "render/image.h"
#include "render/ray_log.h"
#include "render/ray_offset.h"
#include "render/sampler.h"
#include "render/tiles.h"
#include "scene/scene.h"

namespace raypack {

struct WhittedOptions {
    int width = 512;
    int height = 512;
    int max_depth = 5;  ///< the eye ray has depth 1 (SPD protocol: 5)
    /// Distance attenuation 1 / (c2 r^2 + c1 r + c0) per light; NFF has none.
    float atten_c0 = 1, atten_c1 = 0, atten_c2 = 0;
    /// How secondary-ray origins move off the surface (render/ray_offset.h).
    OffsetPolicy offset = kDefaultOffset;
    /// Eye rays are traced as packets of this width (1, 4, 8, 16), each
    /// covering a compact block of pixels.
    int packet = 1;
    /// Reflection, refraction and shadow rays: packets of this width.
    int secondary_packet = 1;
    /// Pixels per tile side; 0: render_tiles' choice. A tile's rays of one
    /// depth form one batch.
    int tile_size = 0;
    /// Distribution ray tracing: the effects below are sampled. Off (the
    /// Whitted integrator), one ray per pixel centre, the lens is a pinhole,
    /// glossy surfaces are mirrors and each area light is one point light
    /// (its centre; a sphere's point facing the shaded point).
    bool distribution = false;
    /// Hits become shading points in SIMD lanes (the same bits as one by
    /// one); false: one by one, the reference the lanes are tested against.
    bool surface_lanes = true;
    int spp = 1;                                   ///< camera samples per pixel
    SamplerKind sampler = SamplerKind::Stratified;
    std::uint64_t seed = 1;
    int light_samples = 1;                         ///< shadow rays per area light per camera sample
    PixelFilter filter = PixelFilter::Box;
    /// Adaptive supersampling instead of spp (distribution only; 0 = off):
    /// rays through the pixel corners, and a square whose corners differ by
    /// at least this much in some channel is split in four, down to
    /// `adaptive_depth` levels (POV-Ray's +AM2 method). Lens, light and lobe
    /// samples are keyed by the point, so shared corners agree.
    float adaptive_threshold = 0;
    int adaptive_depth = 3;
    /// A fresh film of width x height made by the caller (sampled renders:
    /// distribution with spp > 1, path), so that its pages are faulted in
    /// before the render's clock starts, as the image's are; nullptr: the
    /// render makes its own. The render adds its samples to it.
    Film* film = nullptr;
    /// Called after each finished tile with the number of pixels done so far
    /// (from any thread; for progress reports). May be empty.
    void (*progress)(void* context, std::uint64_t pixels_done, std::uint64_t pixels_total) = nullptr;
    void* progress_context = nullptr;
    /// If set, every ray the render traces is added to it (render --save-rays).
    RayLog* ray_log = nullptr;
};

/// Ray counts in the SPD Readme's terms, to compare with its statistics table.
struct RenderStats {
    std::uint64_t eye_rays = 0;
    std::uint64_t eye_hits = 0;
    std::uint64_t reflect_rays = 0;
    std::uint64_t refract_rays = 0;
    std::uint64_t shadow_rays = 0;
    std::uint64_t diffuse_rays = 0;  ///< path tracing's diffuse bounces
    double render_ms = 0;
    /// Adaptive supersampling: the points traced per pixel, on average.
    double samples_per_pixel = 0;
    /// Sampled renders: the RMS standard error of the pixel means (Film::noise_rms); 0 for Whitted.
    double noise_rms = 0;

    std::uint64_t total_rays() const { return eye_rays + reflect_rays + refract_rays + shadow_rays + diffuse_rays; }
    RenderStats& operator+=(const RenderStats& o);
};

/// The tiles a render walks (render/tiles.h): sides of options.tile_size,
/// or by default 16, except where streams will carry the reflections (one
/// sample a pixel, a structure with streams, and spheres and cones that
/// reflect or transmit making up half the scene or more: rings, balls),
/// whose batches want to be large: 64 (rings and balls 1.28x and 1.24x
/// faster than in tiles of 16 at one thread; at two, 4-9% faster than 32
/// once the threads share one heap, app/heap_pages.cpp). Tiles of 64
/// everywhere were 2-4% slower at one thread on gears, mount and teapot,
/// and the short renders lost much of two threads' speed-up (tetra 1.63x
/// -> 1.28x, mount 1.76x -> 1.12x).
TileGrid render_tiles(const Scene& scene, const WhittedOptions& options, const Accel& accel,
                      bool one_sample_a_pixel);

/// Renders one sample per pixel centre, tiles in parallel with oneTBB (the
/// caller limits threads with tbb::global_control). With one sample a
/// pixel, an `image` that already has the options' size is written in place.
RenderStats render_whitted(const Scene& scene, const Accel& accel, const WhittedOptions& options, Image& image);

/// Colour seen along each of `rays` (depth 1), traced as one wavefront.
void whitted_radiance(const Scene& scene, const Accel& accel, const WhittedOptions& options,
                      std::span<const Rayf> rays, std::span<Vec3f> colors, RenderStats& stats);

/// Colour seen along one ray (depth 1), for tests and tools.
Vec3f whitted_radiance(const Scene& scene, const Accel& accel, const WhittedOptions& options, const Rayf& ray);

}  // namespace raypack
