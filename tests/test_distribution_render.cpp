// The distribution integrator (render/whitted.h, distribution = true)
// against closed forms: a pixel cut by an edge converges to the covered
// fraction, a plane in focus looks the same through the lens as through the
// pinhole, and the soft shadow of a rendered scene lies between umbra and
// full light; images do not depend on the thread count.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <bit>
#include <cmath>

#include "accel/accel.h"
#include "render/whitted.h"
#include "scene/load.h"
#include "scene/nff_text.h"
#include "test_paths.h"

namespace raypack {
namespace {

/// A camera at the origin looking down -z at the plane z = -10, 32 x 32
/// pixels; no lights, so a surface shows its ambient colour, 0.5 x its fill
/// colour (the SPD rule with L = 0 counted as 1).
Scene plane_scene() {
    Scene s;
    s.camera.from = {0, 0, 0};
    s.camera.at = {0, 0, -1};
    s.camera.up = {0, 1, 0};
    s.camera.fov_deg = 30;
    s.camera.width = s.camera.height = 32;
    s.has_camera = true;
    s.background = {0, 0, 0};
    return s;
}

WhittedOptions distribution(int spp, SamplerKind sampler) {
    WhittedOptions o;
    o.width = o.height = 32;
    o.distribution = true;
    o.spp = spp;
    o.sampler = sampler;
    return o;
}

TEST(DistributionRender, PixelCutByAnEdgeConvergesToTheCoveredFraction) {
    Scene s = plane_scene();
    s.materials.push_back({});  // white
    // Image plane step per pixel at unit distance: 2 tan(15 deg) / 31 (NFF's
    // angle spans the centres of the outer rows). Put the edge x = X at
    // image column 10.3: pixel 10 is covered over 0.7 of its width.
    const double step = 2 * std::tan(15 * M_PI / 180) / 31;
    const float edge = float((10.3 - 16) * step * 10);
    s.add_triangle({edge, -100, -10}, {100, -100, -10}, {edge, 100, -10}, 0);
    s.update_features();
    const auto accel = build_accel(s, AccelConfig{});
    for (SamplerKind k : {SamplerKind::Stratified, SamplerKind::Sobol, SamplerKind::Random}) {
        Image image;
        render_whitted(s, *accel, distribution(1024, k), image);
        SCOPED_TRACE(sampler_name(k));
        const double tolerance = k == SamplerKind::Random ? 0.05 : 0.01;
        for (int y : {3, 16, 28}) {
            EXPECT_NEAR(image.at(10, y).x, 0.5 * 0.7, 0.5 * tolerance);
            EXPECT_EQ(image.at(9, y).x, 0.0f);
            EXPECT_EQ(image.at(11, y).x, 0.5f);
        }
    }
    // Whitted: the pixel centre is covered, so the pixel is fully white.
    WhittedOptions whitted = distribution(1, SamplerKind::Regular);
    whitted.distribution = false;
    Image image;
    render_whitted(s, *accel, whitted, image);
    EXPECT_EQ(image.at(10, 16).x, 0.5f);
}

/// A checkerboard of 1 x 1 squares on the plane z = -10.
Scene checkerboard() {
    Scene s = plane_scene();
    Material black, white;
    black.color = {0, 0, 0};
    s.materials = {white, black};
    for (int i = -6; i < 6; ++i)
        for (int j = -6; j < 6; ++j) {
            const float x = float(i), y = float(j);
            const std::uint32_t m = std::uint32_t((i + j) & 1);
            s.add_triangle({x, y, -10}, {x + 1, y, -10}, {x + 1, y + 1, -10}, m);
            s.add_triangle({x, y, -10}, {x + 1, y + 1, -10}, {x, y + 1, -10}, m);
        }
    s.update_features();
    return s;
}

double mean_abs_difference(const Image& a, const Image& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) sum += std::fabs(double(a.rgb[i]) - double(b.rgb[i]));
    return sum / double(a.rgb.size());
}

TEST(DistributionRender, APlaneInFocusIsSharpThroughTheLens) {
    Scene s = checkerboard();
    const auto accel = build_accel(s, AccelConfig{});
    const WhittedOptions o = distribution(64, SamplerKind::Stratified);
    Image pinhole, focused, blurred;
    render_whitted(s, *accel, o, pinhole);
    s.camera.lens_radius = 0.5f;
    s.camera.focus_distance = 10;  // the checkerboard's plane
    render_whitted(s, *accel, o, focused);
    s.camera.focus_distance = 5;
    render_whitted(s, *accel, o, blurred);
    // The same pixel positions reach the same points of the plane: only
    // rounding at the squares' edges differs.
    EXPECT_LT(mean_abs_difference(focused, pinhole), 1e-3);
    // Out of focus the circle of confusion on the plane has radius
    // 0.5 |10 - 5| / 5 = 0.5 squares: the edges blur visibly.
    EXPECT_GT(mean_abs_difference(blurred, pinhole), 0.03);
}

TEST(DistributionRender, SoftShadowOfAnAreaLightHasUmbraPenumbraAndFullLight) {
    // The floor z = 0, a strip x in [2, 4] at z = 2 (long in y), a light
    // x, y in [-1, 1] at z = 4 facing down. A floor point x_f sees light
    // point x_l past the strip unless (x_f + x_l) / 2 is in [2, 4]: umbra
    // for x_f in [5, 7], penumbra in [3, 5] (half the light at x_f = 4).
    Scene s = plane_scene();
    s.camera.from = {0, 0, 20};
    s.camera.at = {0, 0, 0};
    s.camera.fov_deg = 60;
    s.camera.width = s.camera.height = 64;
    s.materials.push_back({});
    s.add_triangle({-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, 0);
    s.add_triangle({-50, -50, 0}, {50, 50, 0}, {-50, 50, 0}, 0);
    s.add_triangle({2, -30, 2}, {4, -30, 2}, {4, 30, 2}, 0);
    s.add_triangle({2, -30, 2}, {4, 30, 2}, {2, 30, 2}, 0);
    AreaLight light;
    light.corner = {-1, -1, 4};
    light.edge1 = {0, 2, 0};
    light.edge2 = {2, 0, 0};  // e x f = (0, 0, -4): facing down
    s.area_lights.push_back(light);
    s.update_features();
    const auto accel = build_accel(s, AccelConfig{});
    WhittedOptions o = distribution(16, SamplerKind::Stratified);
    o.light_samples = 16;
    o.width = o.height = 64;
    Image image;
    render_whitted(s, *accel, o, image);
    // Column c's centre sees the floor at x = (c + 0.5 - 32) 20 step.
    const double step = 2 * std::tan(M_PI / 6) / 63;
    const auto floor_x = [&](int c) { return (c + 0.5 - 32) * 20 * step; };
    const auto column = [&](double x) { return int(std::lround(x / (20 * step) + 31.5)); };
    // Ambient 0.5 (one light: sqrt(1) / 2) plus 0.5 kd cos per visible light
    // point, averaged over the light (midpoint rule).
    const auto expected = [&](double xf) {
        double sum = 0;
        const int n = 400;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double xl = -1 + 2 * (i + 0.5) / n, yl = -1 + 2 * (j + 0.5) / n;
                const double mid = (xf + xl) / 2;
                if (mid >= 2 && mid <= 4) continue;
                sum += 4 / std::sqrt((xl - xf) * (xl - xf) + yl * yl + 16);
            }
        return 0.5 + 0.5 * sum / (n * n);
    };
    const int row = 31;  // the floor's y = -0.18 there: close enough to the strip's middle
    for (double x : {6.0 /* umbra */, 8.0 /* penumbra: half the light */, 7.4, 8.6, -5.0 /* full light */}) {
        const int c = column(x);
        // Seen past the strip: the camera ray crosses z = 2 at 0.9 x.
        ASSERT_FALSE(0.9 * floor_x(c) >= 2 && 0.9 * floor_x(c) <= 4);
        EXPECT_NEAR(image.at(c, row).x, expected(floor_x(c)), 0.03) << "floor x " << floor_x(c);
    }
    EXPECT_NEAR(image.at(column(6), row).x, 0.5f, 1e-6f);  // umbra: ambient alone
}

TEST(DistributionRender, NoiseEstimateFallsAsOneOverRootSamples) {
    // Random sampling: the standard error of a pixel mean is sigma / sqrt(n),
    // so 4x the samples halve the estimate; and it predicts the actual error
    // against a converged render.
    const Scene s = load_scene("gen:cornell:1");
    const auto accel = build_accel(s, AccelConfig{});
    WhittedOptions o = distribution(16, SamplerKind::Random);
    o.light_samples = 1;
    Image i16, i64, reference;
    const double n16 = render_whitted(s, *accel, o, i16).noise_rms;
    o.spp = 64;
    const double n64 = render_whitted(s, *accel, o, i64).noise_rms;
    EXPECT_NEAR(n16 / n64, 2.0, 0.2);
    o.spp = 2048;
    o.sampler = SamplerKind::Sobol;
    render_whitted(s, *accel, o, reference);
    double sum = 0;
    for (std::size_t i = 0; i < i16.rgb.size(); ++i) sum += std::pow(double(i16.rgb[i]) - reference.rgb[i], 2);
    const double error = std::sqrt(sum / double(i16.rgb.size()));
    EXPECT_NEAR(error / n16, 1.0, 0.2) << "measured error " << error << ", estimated " << n16;
}

/// RMS difference of two images.
double rms(const Image& a, const Image& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) sum += std::pow(double(a.rgb[i]) - b.rgb[i], 2);
    return std::sqrt(sum / double(a.rgb.size()));
}

TEST(DistributionRender, AdaptiveSupersamplingMatchesUniformErrorWithFewerSamples) {
    // An edge-dominated image: the checkerboard, seen at an angle so that
    // its edges cross pixels at every position.
    Scene s = checkerboard();
    s.camera.from = {0.3f, -3.0f, 0};
    s.camera.at = {0, 0, -10};
    const auto accel = build_accel(s, AccelConfig{});
    Image reference;
    render_whitted(s, *accel, distribution(1024, SamplerKind::Sobol), reference);
    WhittedOptions uniform = distribution(16, SamplerKind::Stratified);
    Image u;
    render_whitted(s, *accel, uniform, u);
    WhittedOptions adaptive = distribution(1, SamplerKind::Stratified);
    adaptive.adaptive_threshold = 0.1f;
    adaptive.adaptive_depth = 3;
    Image a;
    const RenderStats st = render_whitted(s, *accel, adaptive, a);
    // Measured: 16 stratified samples per pixel give 0.0142, adaptive 0.0091
    // with 13.8 points per pixel (32 x 32 pixels, nearly all on an edge).
    EXPECT_LT(st.samples_per_pixel, 16.0);
    EXPECT_LT(rms(a, reference), rms(u, reference)) << st.samples_per_pixel << " points per pixel";
    // Flat regions stay at the shared corners: about one point per pixel.
    Scene flat = plane_scene();
    flat.materials.push_back({});
    flat.add_triangle({-100, -100, -10}, {100, -100, -10}, {100, 100, -10}, 0);
    flat.add_triangle({-100, -100, -10}, {100, 100, -10}, {-100, 100, -10}, 0);
    flat.update_features();
    const auto flat_accel = build_accel(flat, AccelConfig{});
    Image f;
    EXPECT_LT(render_whitted(flat, *flat_accel, adaptive, f).samples_per_pixel, 1.2);
    EXPECT_NEAR(f.at(7, 9).x, 0.5f, 1e-6f);
}

TEST(DistributionRender, SameImageForAnyThreadCount) {
    const Scene s = load_scene("gen:cornell:2");
    const auto accel = build_accel(s, AccelConfig{});
    WhittedOptions o = distribution(8, SamplerKind::Sobol);
    o.width = o.height = 48;
    o.light_samples = 2;
    Image one, two;
    RenderStats stats_one, stats_two;
    {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        stats_one = render_whitted(s, *accel, o, one);
    }
    {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        stats_two = render_whitted(s, *accel, o, two);
    }
    EXPECT_EQ(one.rgb, two.rgb);
    // The noise estimate too: tiles resolve on their threads, and their
    // parts add up in tile order.
    EXPECT_EQ(stats_one.noise_rms, stats_two.noise_rms);
    // A film and an image the caller made beforehand (the command line's
    // way) take the samples and give the same image; a film of another size
    // is left alone.
    Film film(o.width, o.height), other(5, 3);
    Image three(o.width, o.height), four;
    o.film = &film;
    render_whitted(s, *accel, o, three);
    EXPECT_EQ(three.rgb, one.rgb);
    EXPECT_EQ(film.resolve().rgb, one.rgb);
    EXPECT_NEAR(film.noise_rms(), stats_one.noise_rms, 1e-12 * stats_one.noise_rms);  // whole film at once
    EXPECT_GT(stats_one.noise_rms, 0.0);
    o.film = &other;
    render_whitted(s, *accel, o, four);
    EXPECT_EQ(four.rgb, one.rgb);
    EXPECT_EQ(other.resolve().rgb, std::vector<float>(5 * 3 * 3, 0.0f));
}

TEST(DistributionRender, SurfacesInLanesAreTheScalarPointsBitForBit) {
    // Hits become shading points in SIMD lanes (WhittedOptions::surface_lanes)
    // in both integrators: against one by one on scenes with parallelogram
    // and sphere lights (whose surfaces camera rays see), a lens, glossy and
    // glass surfaces, both offsets the lanes compute; smooth triangles
    // (teapot), cones (rings), and instanced primitives beside the scene's
    // own in one block of lanes (the lanes gather records of the scene's
    // primitives and fall back to one by one for the others).
    const std::string instanced = R"(v
from 0 -6 2
at 0 0 0
up 0 0 1
angle 40
hither 0.01
resolution 40 40
b 0.1 0.1 0.2
l 2 -4 5
f 0.8 0.3 0.3 0.7 0.5 20 0 1
begin leaf
s 0 0 0.5 0.5
p 3 -1 -1 0 1 -1 0 0 1 0
end
inst leaf 1 0 0 -1  0 1 0 0  0 0 1 0
inst leaf 0 -2 0 1.5  1 0 0 0  0 0 2 0
s 0 0.5 -0.5 0.6
p 4 -3 -3 -1 3 -3 -1 3 3 -1 -3 3 -1
)";
    const std::vector<std::string> specs = {"gen:cornell:2", "gen:balls:2:area-lights+lens+glossy", "gen:rings:1",
                                            std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff", "instanced"};
    for (const std::string& spec : specs) {
        const Scene s = spec == "instanced" ? load_nff_text(instanced, "instanced.nff") : load_scene(spec);
        const auto accel = build_accel(s, AccelConfig{});
        for (const bool sampled : {false, true}) {
            for (const OffsetPolicy offset : {OffsetPolicy::Scaled, OffsetPolicy::Epsilon}) {
                WhittedOptions o = distribution(sampled ? 4 : 1, SamplerKind::Stratified);
                o.distribution = sampled;
                o.width = o.height = 40;
                o.light_samples = 2;
                o.offset = offset;
                Image lanes, scalar;
                const RenderStats a = render_whitted(s, *accel, o, lanes);
                o.surface_lanes = false;
                const RenderStats b = render_whitted(s, *accel, o, scalar);
                EXPECT_GT(a.shadow_rays, 1000u) << spec;
                EXPECT_EQ(a.shadow_rays, b.shadow_rays) << spec;
                EXPECT_EQ(a.reflect_rays, b.reflect_rays) << spec;
                EXPECT_EQ(a.refract_rays, b.refract_rays) << spec;
                ASSERT_EQ(lanes.rgb.size(), scalar.rgb.size());
                std::size_t differ = 0;
                for (std::size_t i = 0; i < lanes.rgb.size(); ++i)
                    differ += std::bit_cast<std::uint32_t>(lanes.rgb[i]) != std::bit_cast<std::uint32_t>(scalar.rgb[i]);
                EXPECT_EQ(differ, 0u) << spec << (sampled ? " distribution " : " whitted ") << offset_policy_name(offset);
            }
        }
    }
}

}  // namespace
}  // namespace raypack
