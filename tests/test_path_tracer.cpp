// The path tracer (render/path_tracer.h) against the furnace: inside a
// closed diffuse enclosure of albedo a that emits radiance E everywhere,
// every pixel converges to E (1 + a + a^2 + ...) = E / (1 - a); Russian
// roulette leaves the mean unchanged; images do not depend on the thread count.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>
#include <utility>
#include <string>

#include "accel/accel.h"
#include "render/path_tracer.h"
#include "render/ray_offset.h"
#include "scene/load.h"

namespace raypack {
namespace {

/// A sampled render of size x size pixels at spp samples per pixel.
WhittedOptions sampled(int size, int spp) {
    WhittedOptions o;
    o.width = o.height = size;
    o.distribution = true;
    o.spp = spp;
    return o;
}

/// One render with a PathOptions switch on and one with it off.
struct OnAndOff {
    RenderStats on, off;
    Image on_image, off_image;
    /// Pixel channels whose bits differ between the two images.
    std::size_t differing() const {
        EXPECT_EQ(on_image.rgb.size(), off_image.rgb.size());
        std::size_t differ = 0;
        for (std::size_t i = 0; i < std::min(on_image.rgb.size(), off_image.rgb.size()); ++i)
            differ += std::bit_cast<std::uint32_t>(on_image.rgb[i]) != std::bit_cast<std::uint32_t>(off_image.rgb[i]);
        return differ;
    }
};

OnAndOff render_on_and_off(const Scene& s, const Accel& accel, const WhittedOptions& o, PathOptions path,
                           bool PathOptions::*option) {
    OnAndOff r;
    path.*option = true;
    r.on = render_path(s, accel, o, path, r.on_image);
    path.*option = false;
    r.off = render_path(s, accel, o, path, r.off_image);
    return r;
}

std::uint64_t bounce_rays(const RenderStats& r) { return r.diffuse_rays + r.reflect_rays + r.refract_rays; }

/// The unit cube, each face a parallelogram light facing inward, of
/// albedo `a`; the camera at its centre.
Scene furnace(float a) {
    std::ostringstream nff;
    nff << "v\nfrom 0.5 0.5 0.5\nat 0.5 0.5 0\nup 0 1 0\nangle 100\nhither 0\nresolution 8 8\n";
    nff << "f 1 1 1 " << a << " 0 0 0 1\n";
    nff << "la 0 0 0  1 0 0  0 1 0\nla 0 0 1  0 1 0  1 0 0\n"   // z = 0, z = 1
        << "la 0 0 0  0 1 0  0 0 1\nla 1 0 0  0 0 1  0 1 0\n"   // x = 0, x = 1
        << "la 0 0 0  0 0 1  1 0 0\nla 0 1 0  1 0 0  0 0 1\n";  // y = 0, y = 1
    std::istringstream in(nff.str());
    return load_nff(in, "furnace");
}

struct Estimate {
    double mean, standard_error;
};

Estimate render_furnace(const Scene& s, int rr_depth, int max_depth, int spp, std::uint64_t seed) {
    const auto accel = build_accel(s, AccelConfig{});
    WhittedOptions o = sampled(8, spp);
    o.seed = seed;
    o.sampler = SamplerKind::Random;
    PathOptions path;
    path.rr_depth = rr_depth;
    path.max_depth = max_depth;
    Image image;
    render_path(s, *accel, o, path, image);
    // Red channel only: the grey furnace's channels are the same numbers.
    double sum = 0, sum_sq = 0;
    const std::size_t n = image.rgb.size() / 3;
    for (std::size_t i = 0; i < n; ++i) {
        const double v = image.rgb[3 * i];
        sum += v;
        sum_sq += v * v;
    }
    const double mean = sum / double(n), var = sum_sq / double(n) - mean * mean;
    return {mean, std::sqrt(std::max(0.0, var) / double(n))};
}

TEST(PathTracer, FurnaceConvergesToEmissionOverOneMinusAlbedo) {
    for (float a : {0.5f, 0.8f}) {
        const Scene s = furnace(a);
        const double expected = 1.0 / (1.0 - a);  // E = 1 (the lights' default colour)
        // Without roulette: 64 vertices leave a^64 of the sum out.
        const Estimate fixed = render_furnace(s, 1000, 64, 512, 1);
        EXPECT_NEAR(fixed.mean, expected, 0.01 * expected) << "albedo " << a;
        // With roulette from the first bounce.
        const Estimate rr = render_furnace(s, 0, 1000, 2048, 2);
        EXPECT_NEAR(rr.mean, expected, 0.01 * expected) << "albedo " << a << " se " << rr.standard_error;
        EXPECT_LT(std::fabs(rr.mean - fixed.mean), 3 * std::hypot(rr.standard_error, fixed.standard_error))
            << "albedo " << a;
        // A cap of D vertices sums the first D terms: (1 - a^D) / (1 - a).
        const Estimate capped = render_furnace(s, 1000, 3, 512, 3);
        const double three = (1 - std::pow(a, 3)) / (1 - a);
        EXPECT_NEAR(capped.mean, three, 0.01 * three) << "albedo " << a;
    }
}

TEST(PathTracer, SameImageForAnyThreadCount) {
    const Scene s = load_scene("gen:cornell:2");
    const auto accel = build_accel(s, AccelConfig{});
    WhittedOptions o = sampled(40, 4);
    o.sampler = SamplerKind::Sobol;
    Image one, two;
    double noise_one = 0, noise_two = 0;
    {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        noise_one = render_path(s, *accel, o, PathOptions{}, one).noise_rms;
    }
    {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        noise_two = render_path(s, *accel, o, PathOptions{}, two).noise_rms;
    }
    EXPECT_EQ(one.rgb, two.rgb);
    EXPECT_EQ(noise_one, noise_two);  // tiles' parts summed in tile order
    EXPECT_GT(noise_one, 0.0);
    // A film and an image the caller made beforehand take the samples and
    // give the same image.
    Film film(o.width, o.height);
    Image three(o.width, o.height);
    o.film = &film;
    render_path(s, *accel, o, PathOptions{}, three);
    EXPECT_EQ(three.rgb, one.rgb);
    EXPECT_EQ(film.resolve().rgb, one.rgb);
    EXPECT_NEAR(film.noise_rms(), noise_one, 1e-12 * noise_one);
}

TEST(PathTracer, VerticesInLanesAreTheScalarVerticesBitForBit) {
    // Diffuse vertices go through SIMD lanes (PathOptions::lanes), the rest
    // one by one: every light kind (point, distant, parallelogram, sphere),
    // every material part (diffuse, mirror, glossy, glass), both offsets the
    // lanes compute, random and low-discrepancy draws, roulette from the
    // first bounce; the image and every ray count must be the scalar ones.
    std::ostringstream nff;
    nff << "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 50\nhither 0\nresolution 24 24\n"
        << "b 0.1 0.2 0.3\n"
        << "l 3 -3 5 0.6 0.6 0.5\nld -1 1 -2 0.4 0.4 0.4\nla -1 -1 4  2 0 0  0 2 0  2 2 2\nls 2 2 3 0.3 1 0.8 0.8\n"
        << "f 0.8 0.5 0.3 0.9 0.1 10 0 1\np 4\n-4 -4 0\n4 -4 0\n4 4 0\n-4 4 0\n"   // diffuse floor, a little specular
        << "f 0.9 0.9 0.9 0 1 0 0 1\ns -1 0 1 0.7\n"                              // mirror
        << "f 0.9 0.7 0.6 0.3 0.6 20 0 1\ns 1.8 -1.2 0.4 0.4\n"                   // diffuse and mirror
        << "gloss 40\nf 0.3 0.8 0.3 0.5 0.5 20 0 1\ns 1 0 1 0.7\ngloss 0\n"       // glossy and diffuse
        << "f 1 1 1 0.1 0.1 10 0.8 1.5\ns 0 -1.5 0.6 0.5\n"                       // glass
        << "f 0.2 0.4 0.9 1 0 0 0 1\np 3\n-3 3 0\n3 3 0\n0 3 3\n";              // diffuse wall
    std::istringstream in(nff.str());
    const Scene s = load_nff(in, "lanes");
    const auto accel = build_accel(s, AccelConfig{});
    // One sample per pixel shows a sample's radiance in its pixel, where an
    // ulp of one shadow ray's contribution is not lost in a sum.
    for (const auto& [sampler, spp] : {std::pair{SamplerKind::Random, 1}, std::pair{SamplerKind::Sobol, 8}}) {
        for (const OffsetPolicy offset : {OffsetPolicy::Scaled, OffsetPolicy::Epsilon}) {
            WhittedOptions o = sampled(spp == 1 ? 64 : 24, spp);
            o.sampler = sampler;
            o.offset = offset;
            PathOptions path;
            path.rr_depth = 1;
            path.max_depth = 6;
            const OnAndOff r = render_on_and_off(s, *accel, o, path, &PathOptions::lanes);
            const RenderStats &a = r.on, &b = r.off;
            EXPECT_GT(a.diffuse_rays, 1000u);
            EXPECT_GT(a.reflect_rays, 100u);
            EXPECT_GT(a.refract_rays, 100u);
            EXPECT_EQ(a.diffuse_rays, b.diffuse_rays);
            EXPECT_EQ(a.shadow_rays, b.shadow_rays);
            EXPECT_EQ(a.reflect_rays, b.reflect_rays);
            EXPECT_EQ(a.refract_rays, b.refract_rays);
            EXPECT_EQ(r.differing(), 0u) << sampler_name(sampler) << " spp " << spp << " " << offset_policy_name(offset);
        }
    }
}

TEST(PathTracer, RaysThatCannotCarryLightAreNotTracedAndTheImageStays) {
    // No area light and a black background: a ray of the last depth could
    // only find a surface whose lighting is never computed. Without it
    // (PathOptions::skip_dark_rays) the image is the same bit for bit, in
    // lanes and one by one, the shadow rays are the same, and the bounce
    // rays fewer; at depth 2 no bounce ray is left at all.
    std::ostringstream nff;
    nff << "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 50\nhither 0\nresolution 32 32\n"
        << "b 0 0 0\nl 3 -3 5 0.6 0.6 0.5\nld -1 1 -2 0.4 0.4 0.4\n"
        << "f 0.8 0.5 0.3 0.9 0.1 10 0 1\np 4\n-4 -4 0\n4 -4 0\n4 4 0\n-4 4 0\n"  // diffuse floor
        << "f 0.9 0.9 0.9 0 1 0 0 1\ns -1 0 1 0.7\n"                             // mirror
        << "gloss 40\nf 0.3 0.8 0.3 0.5 0.5 20 0 1\ns 1 0 1 0.7\ngloss 0\n"      // glossy and diffuse
        << "f 1 1 1 0.1 0.1 10 0.8 1.5\ns 0 -1.5 0.6 0.5\n";                     // glass
    std::istringstream in(nff.str());
    const Scene s = load_nff(in, "dark");
    const auto accel = build_accel(s, AccelConfig{});
    for (const int depth : {2, 3}) {
        for (const bool lanes : {true, false}) {
            const WhittedOptions o = sampled(32, 4);
            PathOptions path;
            path.rr_depth = 1;  // roulette where the rays are skipped too
            path.max_depth = depth;
            path.lanes = lanes;
            const OnAndOff r = render_on_and_off(s, *accel, o, path, &PathOptions::skip_dark_rays);
            EXPECT_EQ(r.on.eye_rays, r.off.eye_rays);
            EXPECT_EQ(r.on.shadow_rays, r.off.shadow_rays);
            EXPECT_GT(r.on.shadow_rays, 1000u);
            if (depth == 2) EXPECT_EQ(bounce_rays(r.on), 0u);
            else EXPECT_GT(bounce_rays(r.on), 1000u);
            EXPECT_GT(bounce_rays(r.off), bounce_rays(r.on) + 100) << depth;
            EXPECT_EQ(r.differing(), 0u) << "depth " << depth << (lanes ? " lanes" : " one by one");
        }
    }
    // Under a sky every ray may find light: all of them are traced.
    Scene sky = s;
    sky.background = {0.1f, 0.2f, 0.3f};
    const WhittedOptions o = sampled(16, 2);
    PathOptions path;
    path.max_depth = 3;
    const OnAndOff r = render_on_and_off(sky, *accel, o, path, &PathOptions::skip_dark_rays);
    EXPECT_GT(r.on.diffuse_rays, 100u);
    EXPECT_EQ(bounce_rays(r.on), bounce_rays(r.off));
}

}  // namespace
}  // namespace raypack
