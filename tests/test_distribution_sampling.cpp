// The warps and samples of distribution ray tracing against closed forms:
// the Phong lobe's moments, the concentric disc, area-light sampling (the
// solid angle of a sphere, the penumbra behind an edge traced through a real
// structure), and the thin lens (focus plane and circle of confusion).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "accel/accel.h"
#include "render/light_sampling.h"
#include "render/sampler.h"
#include "render/sampling.h"
#include "render/sin_cos_turns.h"
#include "render/camera_samples.h"
#include "render/thin_lens.h"
#include "scene/scene.h"

namespace {

using raypack::AreaLight;
using raypack::AreaLightShape;
using raypack::Sample2;
using raypack::Sampler;
using raypack::SamplerKind;
using raypack::Vec3d;
using raypack::Vec3f;

}  // namespace

TEST(PhongLobe, MomentsMatchTheDensity) {
    // For density (n+1)/(2 pi) cos^n: E[cos] = (n+1)/(n+2), E[cos^2] = (n+1)/(n+3).
    const Sampler s(SamplerKind::Random, 1, 5);
    const int count = 200000;
    for (double n : {0.0, 1.0, 10.0, 200.0}) {
        double sum_c = 0, sum_c2 = 0, sum_x = 0, sum_y = 0;
        for (int i = 0; i < count; ++i) {
            const Sample2 u = s.get(std::uint64_t(i), 0, 0);
            const Vec3d d = raypack::phong_lobe(n, double(u.x), double(u.y));
            ASSERT_NEAR(length(d), 1.0, 1e-12);
            ASSERT_GE(d.z, 0.0);
            sum_c += d.z;
            sum_c2 += d.z * d.z;
            sum_x += d.x;
            sum_y += d.y;
        }
        const double mean = sum_c / count, var = sum_c2 / count - mean * mean;
        const double se = std::sqrt(var / count) + 1e-12;
        EXPECT_NEAR(mean, (n + 1) / (n + 2), 4 * se) << "n " << n;
        EXPECT_NEAR(sum_c2 / count, (n + 1) / (n + 3), 1e-3) << "n " << n;
        // Symmetric about the axis: the mean direction is the axis.
        EXPECT_NEAR(sum_x / count, 0.0, 4 * std::sqrt((1 - sum_c2 / count) / 2 / count)) << "n " << n;
        EXPECT_NEAR(sum_y / count, 0.0, 4 * std::sqrt((1 - sum_c2 / count) / 2 / count)) << "n " << n;
    }
}

TEST(PhongLobe, DensityIntegratesToOne) {
    for (double n : {0.0, 3.0, 50.0}) {
        // Midpoint rule in theta; the density has no phi dependence.
        const int steps = 20000;
        double sum = 0;
        for (int i = 0; i < steps; ++i) {
            const double t = (i + 0.5) * (std::numbers::pi / 2) / steps;
            sum += raypack::phong_lobe_pdf(n, std::cos(t)) * std::sin(t) * 2 * std::numbers::pi;
        }
        EXPECT_NEAR(sum * (std::numbers::pi / 2) / steps, 1.0, 1e-6) << "n " << n;
    }
    EXPECT_EQ(raypack::phong_lobe_pdf(5.0, -0.1), 0.0);
}

TEST(ConcentricDisk, UniformOverTheDiscAndContinuous) {
    const Sampler s(SamplerKind::Random, 1, 9);
    const int count = 200000;
    double r2 = 0, x = 0, y = 0;
    for (int i = 0; i < count; ++i) {
        const Sample2 u = s.get(std::uint64_t(i), 0, 0);
        const Vec3d d = raypack::concentric_disk(double(u.x), double(u.y));
        ASSERT_LE(d.x * d.x + d.y * d.y, 1.0 + 1e-12);
        r2 += d.x * d.x + d.y * d.y;
        x += d.x;
        y += d.y;
    }
    EXPECT_NEAR(r2 / count, 0.5, 4 * std::sqrt(1.0 / 12 / count));  // r^2 is uniform on [0, 1]
    EXPECT_NEAR(x / count, 0.0, 0.005);
    EXPECT_NEAR(y / count, 0.0, 0.005);
    // The square's border maps onto the circle, its centre onto the centre.
    for (double t = 0; t <= 1; t += 0.125) {
        const Vec3d e = raypack::concentric_disk(t, 1.0);
        EXPECT_NEAR(e.x * e.x + e.y * e.y, 1.0, 1e-12);
    }
    const Vec3d c = raypack::concentric_disk(0.5, 0.5);
    EXPECT_EQ(c.x, 0.0);
    EXPECT_EQ(c.y, 0.0);
}

TEST(AreaLightSampling, ParallelogramIsUniformOverItsArea) {
    AreaLight l;
    l.corner = {1, 2, 3};
    l.edge1 = {2, 0, 0};
    l.edge2 = {1, 0, 3};  // sheared: area |e x f| = 6
    const Sampler s(SamplerKind::Stratified, 256, 1);
    Vec3d mean{};
    for (int i = 0; i < 256; ++i) {
        const raypack::LightSample ls = raypack::sample_area_light(l, {0, 0, 0}, s.get(0, i, 0));
        EXPECT_FLOAT_EQ(ls.pdf_area, 1.0f / 6.0f);
        EXPECT_NEAR(ls.normal.y, -1.0f, 1e-6);  // e x f = (0, -6, 0)
        EXPECT_NEAR(ls.point.y, 2.0f, 1e-6);
        mean = mean + Vec3d(ls.point) / 256.0;
    }
    // The centroid of a parallelogram: corner + (e + f) / 2.
    EXPECT_NEAR(mean.x, 2.5, 1e-2);
    EXPECT_NEAR(mean.z, 4.5, 1e-2);
}

TEST(AreaLightSampling, SphereCapSamplesGiveTheSphereSolidAngle) {
    // Sum of cos(theta_light) / dist^2 / pdf_area estimates the solid angle
    // the sphere subtends: 2 pi (1 - sqrt(1 - r^2 / d^2)).
    AreaLight l;
    l.shape = AreaLightShape::Sphere;
    l.center = {0, 0, 0};
    l.radius = 1;
    const Sampler s(SamplerKind::Sobol, 1024, 3);
    for (float d : {1.5f, 3.0f, 20.0f}) {
        const Vec3f p{0, d, 0};
        double omega = 0;
        for (int i = 0; i < 1024; ++i) {
            const raypack::LightSample ls = raypack::sample_area_light(l, p, s.get(1, i, 0));
            const Vec3f to_p = p - ls.point;
            const float dist = length(to_p);
            const float cos_l = dot(ls.normal, to_p) / dist;
            ASSERT_GE(cos_l, -1e-5f) << "a sample on the hidden side";
            ASSERT_NEAR(length(ls.point - l.center), 1.0f, 1e-5f);
            omega += double(cos_l) / (double(dist) * dist) / double(ls.pdf_area) / 1024;
        }
        const double exact = 2 * std::numbers::pi * (1 - std::sqrt(1 - 1.0 / (double(d) * d)));
        EXPECT_NEAR(omega, exact, 0.01 * exact) << "d " << d;
    }
}

namespace {

/// The penumbra of the material's soft-shadow pages, with a closed form: a
/// unit square light at z = 2, an occluder half-plane x < 0.5 at z = 1. Seen
/// from (x0, 0.5, 0), the light point (qx, qy, 2) is hidden when the ray
/// crosses z = 1 at x = (x0 + qx) / 2 < 0.5, so the visible fraction is x0.
struct Penumbra {
    raypack::Scene scene;
    AreaLight light;
    std::unique_ptr<raypack::Accel> accel;

    Penumbra() {
        scene.materials.push_back({});
        scene.add_triangle({-100, -100, 1}, {0.5f, -100, 1}, {0.5f, 100, 1}, 0);
        scene.add_triangle({-100, -100, 1}, {0.5f, 100, 1}, {-100, 100, 1}, 0);
        scene.update_features();
        light.corner = {0, 0, 2};
        light.edge1 = {0, 1, 0};
        light.edge2 = {1, 0, 0};  // faces down
        accel = raypack::build_accel(scene, raypack::AccelConfig{});
    }

    double visible_fraction(const Sampler& s, std::uint64_t pixel, float x0) const {
        const Vec3f p{x0, 0.5f, 0};
        int visible = 0;
        for (int i = 0; i < s.spp(); ++i) {
            const raypack::LightSample ls = raypack::sample_area_light(light, p, s.get(pixel, i, 2));
            raypack::Rayf r;
            r.org = p;
            r.dir = ls.point - p;
            r.tfar = 1;
            visible += !accel->occluded1(r);
        }
        return double(visible) / s.spp();
    }

    double rms_error(SamplerKind kind, int spp) const {
        const Sampler s(kind, spp, 17);
        double sum_sq = 0;
        int n = 0;
        for (int k = 0; k < 200; ++k) {
            const float x0 = 0.1f + 0.8f * float(k) / 199.0f;
            const double e = visible_fraction(s, std::uint64_t(k), x0) - x0;
            sum_sq += e * e;
            ++n;
        }
        return std::sqrt(sum_sq / n);
    }
};

}  // namespace

TEST(AreaLightSampling, PenumbraConvergesToTheClosedFormAndStratificationPays) {
    const Penumbra pen;
    // Umbra and full light at the ends.
    const Sampler s(SamplerKind::Stratified, 16, 1);
    EXPECT_EQ(pen.visible_fraction(s, 0, -0.2f), 0.0);
    EXPECT_EQ(pen.visible_fraction(s, 0, 1.2f), 1.0);
    for (SamplerKind k : {SamplerKind::Random, SamplerKind::Stratified, SamplerKind::Sobol}) {
        const double e16 = pen.rms_error(k, 16), e256 = pen.rms_error(k, 256);
        EXPECT_LT(e256, e16 / 2) << raypack::sampler_name(k);
        // Random: the binomial sigma sqrt(x (1 - x) / n), about 0.1 at 16.
        EXPECT_LT(e256, 0.04) << raypack::sampler_name(k);
    }
    for (int spp : {16, 64, 256}) {
        const double random = pen.rms_error(SamplerKind::Random, spp);
        const double stratified = pen.rms_error(SamplerKind::Stratified, spp);
        // 2D jitter stratifies the one coordinate that matters here in only
        // sqrt(spp) strata (the material's "stepped look" of a grid, relaxed).
        EXPECT_LT(stratified, random * (spp == 16 ? 0.75 : 0.5)) << "spp " << spp << ": " << stratified << " vs "
                                                                  << random;
    }
}

TEST(ThinLens, RaysOfAPixelMeetOnTheFocusPlaneAndSpreadByTheCircleOfConfusion) {
    raypack::Camera cam;
    cam.from = {1, 2, 3};
    cam.at = {4, 2, -1};
    cam.up = {0, 1, 0};
    cam.fov_deg = 40;
    const raypack::CameraFrame f = raypack::make_camera_frame(cam, 64, 48);
    const float radius = 0.2f, focus = 7.0f;
    const float px = 10.5f, py = 30.5f;
    const raypack::Rayf pinhole = raypack::camera_ray(f, px, py);
    // Radius 0 is the pinhole, bit for bit.
    const raypack::Rayf same = raypack::thin_lens_ray(f, px, py, {0.3f, 0.9f}, 0.0f, focus);
    EXPECT_EQ(same.org, pinhole.org);
    EXPECT_EQ(same.dir, pinhole.dir);
    const Vec3f in_focus = pinhole.org + pinhole.dir * focus;
    for (float d : {2.0f, 7.0f, 20.0f}) {
        const Vec3f centre = pinhole.org + pinhole.dir * d;
        float spread = 0;
        // Points of the square's border land on the aperture's rim.
        for (float t = 0; t < 1; t += 1.0f / 64)
            for (const Sample2 u : {Sample2{t, 0}, Sample2{1, t}, Sample2{t, 1}, Sample2{0, t}}) {
                const raypack::Rayf r = raypack::thin_lens_ray(f, px, py, u, radius, focus);
                EXPECT_NEAR(dot(r.dir, f.forward), 1.0f, 1e-5f);  // tnear stays the hither plane
                EXPECT_NEAR(length(r.org + r.dir * focus - in_focus), 0.0f, 1e-5f);
                spread = std::max(spread, length(r.org + r.dir * d - centre));
            }
        // Thin lens: a point at distance d blurs over radius r |f - d| / f.
        EXPECT_NEAR(spread, radius * std::abs(focus - d) / focus, 1e-4f) << "d " << d;
    }
}

// sin_cos_turns: within 2 ulps of 1 of sin and cos of 2 pi u (double
// reference) over every 2^-20 of a turn and around each quarter, exact at
// whole quarters, and the 8-lane form the scalar one bit for bit.
TEST(SinCosTurns, CloseToLibmAndTheSameInLanes) {
    const auto check = [](float u) {
        float s, c;
        raypack::sin_cos_turns(u, s, c);
        const double phi = 2.0 * std::numbers::pi * double(u);
        EXPECT_NEAR(s, std::sin(phi), 2.4e-7) << "u = " << u;
        EXPECT_NEAR(c, std::cos(phi), 2.4e-7) << "u = " << u;
    };
    for (int i = 0; i <= (1 << 20); ++i) check(float(i) * 0x1.0p-20f);
    for (int q = 0; q <= 4; ++q)
        for (int k = -64; k <= 64; ++k) check(std::nextafter(0.25f * float(q), k < 0 ? -1.0f : 2.0f) + float(k) * 1e-7f);
    const float quarters[5][2] = {{0, 1}, {1, 0}, {0, -1}, {-1, 0}, {0, 1}};
    for (int q = 0; q <= 4; ++q) {
        float s, c;
        raypack::sin_cos_turns(0.25f * float(q), s, c);
        EXPECT_EQ(std::fabs(s), std::fabs(quarters[q][0])) << q;
        EXPECT_EQ(c, quarters[q][1]) << q;
    }
#if defined(__AVX2__)
    using F = raypack::vfloat<8>;
    alignas(32) float u[8], s8[8], c8[8];
    for (int i = 0; i < (1 << 16); i += 8) {
        for (int l = 0; l < 8; ++l) u[l] = float(i + l) * 0x1.0p-16f * 1.5f - 0.25f;  // negative and past 1 too
        F s, c;
        raypack::sin_cos_turns(F::load_aligned(u), s, c);
        s.store_aligned(s8);
        c.store_aligned(c8);
        for (int l = 0; l < 8; ++l) {
            float s1, c1;
            raypack::sin_cos_turns(u[l], s1, c1);
            ASSERT_EQ(std::bit_cast<std::uint32_t>(s1), std::bit_cast<std::uint32_t>(s8[l])) << u[l];
            ASSERT_EQ(std::bit_cast<std::uint32_t>(c1), std::bit_cast<std::uint32_t>(c8[l])) << u[l];
        }
    }
#endif
}

// CameraSampleBatch draws a pinhole's box-filtered rays eight at a time:
// each ray is camera_ray_of_sample's bit for bit, whether a pixel's samples
// fill the lanes or lanes span pixels, and in the tail.
TEST(CameraSamples, RaysInLanesAreTheScalarRaysBitForBit) {
    raypack::Camera camera;
    camera.from = {1, 2, 3};
    camera.at = {0, 0.5f, 0};
    camera.up = {0, 1, 0};
    camera.fov_deg = 40;
    camera.hither = 0.01f;
    const raypack::CameraFrame frame = raypack::make_camera_frame(camera, 7, 5);
    std::vector<raypack::PixelXY> pixels;
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x) pixels.push_back({x, y});
    for (const int spp : {1, 3, 8, 13, 16}) {
        const Sampler sampler(SamplerKind::Stratified, spp, 7);
        raypack::CameraSampleBatch batch;
        std::vector<raypack::Rayf> rays(pixels.size() * std::size_t(spp));
        batch.draw(frame, camera, sampler, raypack::PixelFilter::Box, pixels, 7, 0, spp, rays.data());
        std::size_t i = 0;
        for (const raypack::PixelXY& px : pixels)
            for (int k = 0; k < spp; ++k, ++i) {
                const raypack::Rayf want = raypack::camera_ray_of_sample(frame, camera, raypack::PixelFilter::Box,
                                                                         batch.position[i], {}, px.x, px.y);
                const float got_f[8] = {rays[i].org.x, rays[i].org.y, rays[i].org.z, rays[i].dir.x,
                                        rays[i].dir.y, rays[i].dir.z, rays[i].tnear, rays[i].tfar};
                const float want_f[8] = {want.org.x, want.org.y, want.org.z, want.dir.x,
                                         want.dir.y, want.dir.z, want.tnear, want.tfar};
                for (int c = 0; c < 8; ++c)
                    ASSERT_EQ(std::bit_cast<std::uint32_t>(got_f[c]), std::bit_cast<std::uint32_t>(want_f[c]))
                        << "spp " << spp << " sample " << i << " field " << c;
            }
    }
}
