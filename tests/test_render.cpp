// Whitted renderer: pixels whose answer is known analytically, and the ray
// statistics of the SPD Readme.
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "accel/accel.h"
#include "render/camera_rays.h"
#include "render/image.h"
#include "render/phong_power.h"
#include "render/whitted.h"
#include "scene/load.h"

namespace raypack {
namespace {

std::uint32_t add_material(Scene& s, Vec3f color, float kd, float ks, float shine, float t, float ior) {
    s.materials.push_back({color, kd, ks, shine, t, ior});
    return std::uint32_t(s.materials.size() - 1);
}

/// Axis-aligned square in the plane `axis` = `at`, spanning [lo, hi] in the
/// other two axes, two triangles whose normal points along +axis (or -axis).
void add_square(Scene& s, int axis, float at, float lo0, float hi0, float lo1, float hi1, bool positive,
                std::uint32_t m) {
    auto point = [&](float a, float b) {
        Vec3f p;
        p[axis] = at;
        p[(axis + 1) % 3] = a;
        p[(axis + 2) % 3] = b;
        return p;
    };
    const Vec3f p00 = point(lo0, lo1), p10 = point(hi0, lo1), p11 = point(hi0, hi1), p01 = point(lo0, hi1);
    if (positive) {
        s.add_triangle(p00, p10, p11, m);
        s.add_triangle(p00, p11, p01, m);
    } else {
        s.add_triangle(p00, p11, p10, m);
        s.add_triangle(p00, p01, p11, m);
    }
}

Rayf ray_from_to(Vec3f from, Vec3f to) {
    Rayf r;
    r.org = from;
    r.dir = to - from;
    return r;
}

void expect_color_near(const Vec3f& got, const Vec3f& want, float tol) {
    EXPECT_NEAR(got.x, want.x, tol);
    EXPECT_NEAR(got.y, want.y, tol);
    EXPECT_NEAR(got.z, want.z, tol);
}

TEST(Render, ShadowedPointIsAmbientOnlyAndLitPointIsLambert) {
    Scene s;
    const Vec3f color{0.8f, 0.6f, 0.4f};
    const std::uint32_t m = add_material(s, color, 0.7f, 0, 0, 0, 1);
    add_square(s, 2, 0.0f, -10, 10, -10, 10, true, m);
    s.add_sphere({0, 0, 2}, 0.5f, m);
    s.lights.push_back({{0, 0, 5}, {1, 1, 1}, false});
    s.update_features();
    const auto accel = build_accel(s, AccelConfig{});
    const WhittedOptions opt;
    const float intensity = 0.5f;  // sqrt(1) / (2 * 1) for one light
    const Vec3f ambient = color * (intensity * 0.7f);

    // The origin lies in the sphere's shadow: ambient only.
    const Vec3f shadowed = whitted_radiance(s, *accel, opt, ray_from_to({3, 0, 1}, {0, 0, 0}));
    expect_color_near(shadowed, ambient, 1e-6f);

    // (2, 0, 0) sees the light: ambient + Kd * cos * colour.
    const Vec3f lit = whitted_radiance(s, *accel, opt, ray_from_to({3, 0, 1}, {2, 0, 0}));
    const float cos_theta = 5.0f / std::sqrt(29.0f);
    expect_color_near(lit, ambient + color * (intensity * 0.7f * cos_theta), 2e-4f);
}

TEST(Render, SpecularHighlightFollowsPhong) {
    Scene s;
    const std::uint32_t m = add_material(s, {1, 1, 1}, 0.0f, 0.5f, 20.0f, 0, 1);
    add_square(s, 2, 0.0f, -10, 10, -10, 10, true, m);
    s.lights.push_back({{-1, 0, 1}, {1, 1, 1}, false});
    s.update_features();
    const auto accel = build_accel(s, AccelConfig{});
    WhittedOptions opt;
    opt.max_depth = 1;  // no reflection ray: only the highlight
    // Viewer at (1, 0, 1) looking at the origin: the mirror direction of the
    // light, R.V = 1, so the highlight is Ks * intensity.
    const Vec3f peak = whitted_radiance(s, *accel, opt, ray_from_to({1, 0, 1}, {0, 0, 0}));
    expect_color_near(peak, Vec3f{0.25f, 0.25f, 0.25f}, 2e-4f);
    // Off the mirror direction: cos^20 of the angle between R and V.
    const Vec3f p{0.5f, 0, 0};
    const Vec3f l = normalize(Vec3f{-1, 0, 1} - p);
    const Vec3f r{-l.x, -l.y, l.z};
    const Vec3f v = normalize(Vec3f{1, 0, 1} - p);
    const float expected = 0.5f * 0.5f * std::pow(dot(r, v), 20.0f);
    const Vec3f off = whitted_radiance(s, *accel, opt, ray_from_to({1, 0, 1}, p));
    EXPECT_NEAR(off.x, expected, 2e-4f);
    EXPECT_LT(off.x, 0.2f);
}

TEST(Render, MirrorShowsTheColourItFaces) {
    Scene s;  // no lights: each surface shows its ambient share only
    const std::uint32_t mirror = add_material(s, {1, 1, 1}, 0.0f, 1.0f, 0, 0, 1);
    const std::uint32_t half_mirror = add_material(s, {1, 1, 1}, 0.0f, 0.5f, 0, 0, 1);
    const std::uint32_t red = add_material(s, {1, 0.2f, 0.1f}, 0.9f, 0, 0, 0, 1);
    add_square(s, 2, 0.0f, -10, 10, -10, 10, true, mirror);
    add_square(s, 2, 0.0f, 20, 40, -10, 10, true, half_mirror);
    add_square(s, 0, -5.0f, -10, 10, 0, 10, true, red);    // wall facing +x behind the mirror
    add_square(s, 0, 45.0f, -10, 10, 0, 10, false, red);   // wall facing -x
    s.update_features();
    const auto accel = build_accel(s, AccelConfig{});
    const WhittedOptions opt;
    const Vec3f wall = Vec3f{1, 0.2f, 0.1f} * (0.5f * 0.9f);
    // Seen directly and in the mirror, the wall has the same colour.
    expect_color_near(whitted_radiance(s, *accel, opt, ray_from_to({5, 0, 5}, {-5, 0, 2})), wall, 1e-6f);
    expect_color_near(whitted_radiance(s, *accel, opt, ray_from_to({5, 0, 5}, {0, 0, 0})), wall, 1e-6f);
    // A half-reflective mirror shows it at half strength.
    expect_color_near(whitted_radiance(s, *accel, opt, ray_from_to({34, 0, 5}, {39, 0, 0})), wall * 0.5f, 1e-6f);
}

/// Glass slab of thickness 1 (z in [-1, 0], ior 1.5) above a floor at z = -2
/// that is red for x < edge and green beyond. A ray at 45 degrees from
/// (0, 0, 1) enters at x = 1, travels at asin(sin 45 / 1.5) inside, leaves
/// parallel to itself and lands at x = 2 + tan(28.13 deg) = 2.5345 instead of
/// the x = 3 a straight ray would reach.
Vec3f slab_colour(float edge, float ior) {
    Scene s;
    const std::uint32_t glass = add_material(s, {1, 1, 1}, 0.0f, 0.0f, 0, 1.0f, ior);
    const std::uint32_t red = add_material(s, {1, 0, 0}, 1.0f, 0, 0, 0, 1);
    const std::uint32_t green = add_material(s, {0, 1, 0}, 1.0f, 0, 0, 0, 1);
    add_square(s, 2, 0.0f, -100, 100, -100, 100, true, glass);
    add_square(s, 2, -1.0f, -100, 100, -100, 100, false, glass);
    add_square(s, 2, -2.0f, -100, edge, -100, 100, true, red);
    add_square(s, 2, -2.0f, edge, 100, -100, 100, true, green);
    s.update_features();
    const auto accel = build_accel(s, AccelConfig{});
    return whitted_radiance(s, *accel, WhittedOptions{}, ray_from_to({0, 0, 1}, {1, 0, 0}));
}

TEST(Render, RefractionThroughSlabShiftsAsSnellSays) {
    const double theta_r = std::asin(std::sin(std::numbers::pi / 4) / 1.5);
    const float landing = float(2.0 + std::tan(theta_r));  // 2.5345
    const Vec3f red{0.5f, 0, 0}, green{0, 0.5f, 0};
    expect_color_near(slab_colour(landing + 0.01f, 1.5f), red, 1e-6f);
    expect_color_near(slab_colour(landing - 0.01f, 1.5f), green, 1e-6f);
    // An index of 1 does not bend the ray: it lands at x = 3.
    expect_color_near(slab_colour(2.99f, 1.0f), green, 1e-6f);
    expect_color_near(slab_colour(3.01f, 1.0f), red, 1e-6f);
}

TEST(Render, TotalInternalReflectionKeepsLightInside) {
    // Leaving glass (ior 1.5) at 60 degrees exceeds the critical angle of
    // 41.8 degrees: the exit ray is reflected back, never reaching the floor
    // below the lower face. Start inside the slab.
    Scene s;
    const std::uint32_t glass = add_material(s, {1, 1, 1}, 0.0f, 0.0f, 0, 1.0f, 1.5f);
    const std::uint32_t red = add_material(s, {1, 0, 0}, 1.0f, 0, 0, 0, 1);
    add_square(s, 2, 0.0f, -100, 100, -100, 100, true, glass);
    add_square(s, 2, -1.0f, -100, 100, -100, 100, false, glass);
    add_square(s, 2, -2.0f, -100, 100, -100, 100, true, red);
    s.update_features();
    const auto accel = build_accel(s, AccelConfig{});
    const float a = float(std::numbers::pi / 3);
    const Vec3f steep = whitted_radiance(s, *accel, WhittedOptions{}, ray_from_to({0, 0, -0.5f}, {std::sin(a), 0, -0.5f - std::cos(a)}));
    EXPECT_EQ(steep.x, 0.0f);  // trapped until the depth limit: the floor is never seen
    const Vec3f gentle = whitted_radiance(s, *accel, WhittedOptions{}, ray_from_to({0, 0, -0.5f}, {0.2f, 0, -1.0f}));
    EXPECT_NEAR(gentle.x, 0.5f, 1e-6f);  // below the critical angle: the red floor
}

TEST(Render, CameraRaysSpanTheFieldOfView) {
    Camera c;
    c.from = {0, 0, 0};
    c.at = {0, 0, -1};
    c.up = {0, 1, 0};
    c.fov_deg = 90;
    const CameraFrame f = make_camera_frame(c, 5, 5);
    // NFF: the angle spans the centres of the top and bottom rows.
    const Rayf top = camera_ray(f, 2.5f, 0.5f), bottom = camera_ray(f, 2.5f, 4.5f);
    EXPECT_NEAR(top.dir.y / -top.dir.z, 1.0f, 1e-6f);
    EXPECT_NEAR(bottom.dir.y / -bottom.dir.z, -1.0f, 1e-6f);
    const Rayf right = camera_ray(f, 4.5f, 2.5f);
    EXPECT_NEAR(right.dir.x / -right.dir.z, 1.0f, 1e-6f);  // right-handed: +x is right when looking down -z
    EXPECT_THROW(make_camera_frame(c, 0, 5), std::invalid_argument);
    c.up = {0, 0, 2};
    EXPECT_THROW(make_camera_frame(c, 5, 5), std::invalid_argument);
}

/// SPD Readme statistics table: eye rays that hit, reflection, refraction and
/// shadow rays, for 513 x 513 eye rays. The Readme expects any classical ray
/// tracer to land within about 10%; we render 512 x 512 pixel centres and
/// scale. (teapot's row is for size 12; the shipped file is size 6.)
struct SpdStats {
    const char* scene;
    double eye_hits, reflect, refract, shadow;
};

TEST(Render, RayCountsMatchTheSpdStatisticsTable) {
    const SpdStats table[] = {
        {"balls", 263169, 175095, 0, 954368},   {"gears", 245086, 304643, 207564, 2246955},
        {"mount", 173125, 354769, 354769, 412922}, {"rings", 263169, 315236, 0, 1085002},
        {"teapot", 161120, 225248, 0, 407656},  {"tetra", 49788, 0, 0, 46112},
        {"tree", 169836, 0, 0, 1097419},
    };
    const double scale = 512.0 * 512.0 / (513.0 * 513.0);
    for (const SpdStats& row : table) {
        SCOPED_TRACE(row.scene);
        const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + row.scene + ".nff");
        const auto accel = build_accel(scene, AccelConfig{});
        Image image;
        const RenderStats st = render_whitted(scene, *accel, WhittedOptions{}, image);
        const double tol = 0.05;
        auto near = [&](double got, double want) {
            if (want == 0) return got == 0;
            return std::fabs(got / (want * scale) - 1.0) <= tol;
        };
        EXPECT_EQ(st.eye_rays, 512u * 512u);
        EXPECT_TRUE(near(double(st.eye_hits), row.eye_hits)) << st.eye_hits;
        EXPECT_TRUE(near(double(st.reflect_rays), row.reflect)) << st.reflect_rays;
        EXPECT_TRUE(near(double(st.refract_rays), row.refract)) << st.refract_rays;
        EXPECT_TRUE(near(double(st.shadow_rays), row.shadow)) << st.shadow_rays;
        for (float v : image.rgb) ASSERT_TRUE(std::isfinite(v));
    }
}

TEST(Render, ImagesRoundTripThroughPngAndExr) {
    const auto dir = std::filesystem::temp_directory_path() / "raypack_test_render";
    std::filesystem::create_directories(dir);
    Image img(7, 5);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x) img.set(x, y, {float(x) / 6.0f, float(y) / 4.0f, 0.25f});
    img.set(0, 0, {2.0f, -1.0f, 0.5f});  // out of range: clamped in PNG, kept in EXR
    const std::string png = (dir / "a.png").string(), exr = (dir / "a.exr").string();
    write_image(png, img);
    write_image(exr, img);
    const Image p = read_image(png), e = read_image(exr);
    ASSERT_EQ(p.width, 7);
    ASSERT_EQ(p.height, 5);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x)
            for (int c = 0; c < 3; ++c) {
                const float want = img.at(x, y)[c];
                EXPECT_NEAR(p.at(x, y)[c], std::clamp(want, 0.0f, 1.0f), 0.5f / 255.0f + 1e-6f);
                EXPECT_NEAR(e.at(x, y)[c], want, 1e-3f * std::max(1.0f, std::fabs(want)));
            }
    // An unknown format fails before anything is written; an existing file survives.
    const std::string keep = (dir / "keep.nosuchformat").string();
    { std::ofstream(keep) << "precious"; }
    EXPECT_THROW(write_image(keep, img), std::runtime_error);
    std::ifstream in(keep);
    std::string content;
    in >> content;
    EXPECT_EQ(content, "precious");
    EXPECT_THROW(write_image((dir / "no_such_dir" / "x.png").string(), img), std::runtime_error);
}

}  // namespace
}  // namespace raypack

namespace raypack {
namespace {

TEST(Render, PacketPrimaryRaysGiveTheSameImage) {
    // Packet lanes run the same operations as single rays, so the hits, and
    // therefore every pixel, are identical.
    const Scene scene = load_scene("gen:balls:2");
    const auto accel = build_accel(scene, AccelConfig{});
    WhittedOptions options;
    options.width = 67;  // not a multiple of the 4 x 4 blocks or the tiles
    options.height = 45;
    Image single, packed;
    render_whitted(scene, *accel, options, single);
    for (int width : {4, 8, 16}) {
        if (!accel->supports_packet(width)) continue;
        options.packet = width;
        const RenderStats st = render_whitted(scene, *accel, options, packed);
        EXPECT_EQ(st.eye_rays, 67u * 45u);
        EXPECT_EQ(packed.rgb, single.rgb) << "packet width " << width;
    }
}

// phong_power: x^n within n |log2 x| 2^-22 of the double-precision power
// (relative), exact at x = 1 and at n = 0, +0 at and below the cut-off the
// Whitted shading skips the call at (exp2(-126 / n), rounded down), and
// the 8-lane form the scalar one bit for bit.
TEST(PhongPower, CloseToPowExactAtTheEndsAndTheSameInLanes) {
    for (const float n : {0.5f, 1.0f, 2.0f, 3.5f, 10.0f, 20.0f, 101.0f, 1000.0f}) {
        for (int k = 1; k <= 1 << 16; ++k) {
            const float x = float(k) * 0x1.0p-16f;
            const double want = std::pow(double(x), double(n));
            if (want < 0x1.0p-124) continue;
            const double bound = (double(n) * std::fabs(std::log2(double(x))) + 1.0) * 0x1.0p-22;
            EXPECT_NEAR(phong_power(x, n) / want, 1.0, bound) << x << "^" << n;
        }
        EXPECT_EQ(phong_power(1.0f, n), 1.0f);
        const float cutoff = std::nextafter(float(std::exp2(-126.0 / double(n))), 0.0f);
        if (cutoff > 0) {
            EXPECT_EQ(phong_power(cutoff, n), 0.0f) << n;
        }
        EXPECT_EQ(phong_power(0.25f, 0.0f), 1.0f);
    }
#if defined(__AVX2__)
    using F = vfloat<8>;
    alignas(32) float x[8], got[8];
    for (const float n : {1.0f, 7.0f, 101.0f}) {
        for (int k = 0; k < 4096; k += 8) {
            for (int l = 0; l < 8; ++l) x[l] = float(k + l + 1) / 4096.0f;
            phong_power(F::load_aligned(x), F(n)).store_aligned(got);
            for (int l = 0; l < 8; ++l)
                ASSERT_EQ(std::bit_cast<std::uint32_t>(got[l]), std::bit_cast<std::uint32_t>(phong_power(x[l], n)))
                    << x[l] << "^" << n;
        }
    }
#endif
}

}  // namespace
}  // namespace raypack
