// Motion blur (NFF shutter / move / two-matrix inst, accel/motion/motion_bvh.h):
// every structure and packet width against brute force at random times, the
// moving scene against static copies at the shutter's ends, surfaces at the
// ray's time, the errors, and renders that converge to the time average.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "oracle_harness.h"
#include "render/image.h"
#include "render/ray_offset.h"
#include "render/surface.h"
#include "render/path_tracer.h"
#include "render/whitted.h"
#include "scene/load.h"
#include "scene/nff_text.h"
#include "scene_errors.h"

namespace raypack {
namespace {

using namespace oracle_harness;

Scene parse(const std::string& text) { return load_nff_text(text, "test.nff"); }

/// Spheres and triangles, some moving (`move`), a static object placed
/// statically and moving (a rotation of 40 degrees over the shutter), on a
/// static floor; shutter [t0, t1]. With `at_end`, the same scene written
/// statically where it is at the shutter's closing (moves added to the
/// positions); with `frozen`, statically at its opening (no `move` lines).
std::string moving_scene_text(unsigned seed, float t0, float t1, bool frozen = false, bool at_end = false) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1);
    std::ostringstream t;
    t.precision(9);
    t << "v from 0 -14 5 at 0 0 0 up 0 0 1 angle 50 hither 0.01 resolution 32 32\n";
    t << "l 5 -5 8\nf 0.8 0.4 0.3 0.7 0.3 20 0 1\n";
    if (!frozen && !at_end) t << "shutter " << t0 << ' ' << t1 << "\n";
    t << "p 4 -6 -6 -1 6 -6 -1 6 6 -1 -6 6 -1\n";
    t << "begin rock\n";
    for (int i = 0; i < 6; ++i) {
        const Vec3f c{u(rng), u(rng), u(rng)};
        t << "p 3 " << c.x << ' ' << c.y << ' ' << c.z << ' ' << c.x + 0.6f << ' ' << c.y << ' ' << c.z << ' ' << c.x
          << ' ' << c.y + 0.6f << ' ' << c.z + 0.3f << "\n";
    }
    t << "s 0 0 0 0.5\nend\n";
    for (int group = 0; group < 8; ++group) {
        const Vec3f d{u(rng) * 2, u(rng) * 2, u(rng)};
        const Vec3f shift = at_end ? d : Vec3f{};
        if (!frozen && !at_end) t << "move " << d.x << ' ' << d.y << ' ' << d.z << "\n";
        for (int i = 0; i < 3; ++i) {
            const Vec3f c = Vec3f{u(rng) * 4, u(rng) * 4, u(rng) * 2} + shift;
            t << "s " << c.x << ' ' << c.y << ' ' << c.z << ' ' << 0.2f + 0.3f * std::fabs(u(rng)) << "\n";
            t << "p 3 " << c.x << ' ' << c.y << ' ' << c.z + 0.6f << ' ' << c.x + 0.7f << ' ' << c.y << ' ' << c.z + 0.6f
              << ' ' << c.x << ' ' << c.y + 0.7f << ' ' << c.z + 0.9f << "\n";
        }
    }
    if (!frozen && !at_end) t << "move 0 0 0\n";
    t << "inst rock 1 0 0 3 0 1 0 3 0 0 1 0\n";
    // A placement turning by 40 degrees about z and rising by 1.
    const float c = std::cos(0.698132f), s = std::sin(0.698132f);
    const std::string start = "1 0 0 -3 0 1 0 2 0 0 1 0";
    std::ostringstream end;
    end.precision(9);
    end << c << ' ' << -s << " 0 -3 " << s << ' ' << c << " 0 2 0 0 1 1";
    if (frozen) t << "inst rock " << start << "\n";
    else if (at_end) t << "inst rock " << end.str() << "\n";
    else t << "inst rock " << start << ' ' << end.str() << "\n";
    return t.str();
}

std::vector<float> random_times(std::mt19937& rng, std::size_t n, float t0, float t1) {
    // Past both ends too: times clamp to the shutter.
    std::uniform_real_distribution<float> u(t0 - 0.25f * (t1 - t0), t1 + 0.25f * (t1 - t0));
    std::vector<float> times(n);
    for (float& x : times) x = u(rng);
    return times;
}

TEST(Motion, LoaderReadsShutterMovesAndTwoMatrixPlacements) {
    const Scene s = parse(
        "shutter 2 4\n"
        "f 1 1 1 1 0 0 0 1\n"
        "s 0 0 0 1\n"
        "move 1 2 3\ns 5 0 0 1\ns 7 0 0 1\n"
        "move 0 0 0\ns 9 0 0 1\n"
        "begin b\ns 0 0 0 1\nend\n"
        "inst b 1 0 0 0 0 1 0 0 0 0 1 0\n"
        "inst b 1 0 0 0 0 1 0 0 0 0 1 0 2 0 0 1 0 2 0 0 0 0 2 0\n"
        "inst b 1 0 0 0 0 1 0 0 0 0 1 0 1 0 0 0 0 1 0 0 0 0 1 0\n"
        "move 0 0 -1\ninst b 1 0 0 0 0 1 0 0 0 0 1 0\n");
    EXPECT_EQ(s.shutter_open, 2.0f);
    EXPECT_EQ(s.shutter_close, 4.0f);
    EXPECT_EQ(s.primitive_count(), 4u);         // two spheres, two static placements
    ASSERT_EQ(s.moving_instances.size(), 3u);   // the group of two spheres, the growing and the sinking placement
    EXPECT_TRUE(s.features.motion);
    EXPECT_EQ(s.hit_id_count(), 4u + 2u + 2u + 1u + 1u);
    // The group's placement: identity to the translation (1, 2, 3).
    const Instance& group = s.moving_instances[0];
    EXPECT_EQ(s.objects[group.object]->primitive_count(), 2u);
    EXPECT_EQ(group.to_world_end.m[0][3], 1.0f);
    EXPECT_EQ(group.to_world_end.m[2][3], 3.0f);
    EXPECT_EQ(s.moving_instances[1].to_world_end.m[1][1], 2.0f);
    EXPECT_EQ(s.moving_instances[2].to_world_end.m[2][3], -1.0f);
    // Ids of the moving placements follow the static ones'.
    EXPECT_EQ(&instance_of_hit_id(s, 4), &s.instances[0]);
    EXPECT_EQ(&instance_of_hit_id(s, 6), &s.moving_instances[0]);
    EXPECT_EQ(&instance_of_hit_id(s, 9), &s.moving_instances[2]);
    // The shutter fraction clamps, and "no time" is the opening.
    EXPECT_EQ(s.shutter_fraction(3.0f), 0.5f);
    EXPECT_EQ(s.shutter_fraction(1.0f), 0.0f);
    EXPECT_EQ(s.shutter_fraction(9.0f), 1.0f);
    EXPECT_EQ(s.shutter_fraction(-INFINITY), 0.0f);
    EXPECT_EQ(s.shutter_fraction(NAN), 0.0f);
    EXPECT_EQ(parse("shutter 1 1\n").shutter_fraction(5.0f), 0.0f);  // no length: frozen at t0
}

TEST(Motion, BadMotionIsAClearError) {
    const BadScene cases[] = {
        {"begin a\nmove 1 0 0\nend\n", 2, "'move' inside object 'a': objects are static"},
        {"begin a\ns 0 0 0 1\nend\nbegin b\ninst a 1 0 0 0 0 1 0 0 0 0 1 0 1 0 0 1 0 1 0 0 0 0 1 0\nend\n", 5,
         "a moving placement inside object 'b'"},
        {"shutter 1 0\n", 1, "shutter closes before it opens"},
        {"shutter 0 1\nshutter 0 2\n", 2, "second 'shutter' line (the first is on line 1)"},
        {"shutter 0 nan\n", 1, "non-finite number 'nan' for shutter closing"},
        {"move 1 inf 0\n", 1, "non-finite number 'inf' for motion"},
        // A half turn about z, interpolated entry by entry, is singular at mid-shutter.
        {"begin a\ns 0 0 0 1\nend\ninst a 1 0 0 0 0 1 0 0 0 0 1 0 -1 0 0 0 0 -1 0 0 0 0 1 0\n", 4,
         "passes through a singular matrix at shutter fraction 0.5"},
        {"begin a\ns 0 0 0 1\nend\ninst a 1 0 0 0 0 1 0 0 0 0 1 0 1 0 0 0 0 0 0 0 0 0 1 0\n", 4,
         "singular instance matrix"},
        {"move 3e38 0 0\nbegin a\ns 0 0 0 1\nend\ninst a 1 0 0 3e38 0 1 0 0 0 0 1 0\n", 5,
         "takes the placement past the float range"},
    };
    expect_scene_errors(cases);
}

/// Every structure at every packet width its queries take, at random times,
/// against brute force at the same times: closest hits and occlusion.
TEST(Motion, EveryStructureAgreesWithBruteForceAtRandomTimes) {
    const Scene scene = parse(moving_scene_text(7, 1.0f, 3.0f));
    ASSERT_EQ(scene.moving_instances.size(), 9u);
    std::mt19937 rng(11);
    std::vector<Rayf> rays = camera_rays(scene, 48);
    for (const Rayf& r : random_rays(scene, rng, 2000, 0.2f)) rays.push_back(r);
    const std::vector<float> times = random_times(rng, rays.size(), 1.0f, 3.0f);
    const auto brute = build_accel(scene, accel_config("brute"));
    std::vector<Hitf> want(rays.size());
    std::vector<std::uint8_t> want_occluded(rays.size());
    brute->intersect_at(1, rays, times, want);
    brute->occluded_at(1, rays, times, want_occluded);
    std::size_t moving_hits = 0;
    for (const Hitf& h : want) moving_hits += h.found() && h.prim >= scene.moving_instances[0].first_hit_id;
    EXPECT_GT(moving_hits, 150u) << "the rays should meet the moving placements";
    for (const char* kind : accel_kinds()) {
        if (is_embree_kind(kind) || std::string(kind) == "brute") continue;
        const auto accel = build_accel(scene, accel_config(kind));
        for (const int width : {1, 4, 8, 16}) {
            if (width > 1 && !accel->supports_packet(width)) continue;
            std::vector<Hitf> got(rays.size());
            std::vector<std::uint8_t> occluded(rays.size());
            accel->intersect_at(width, rays, times, got);
            accel->occluded_at(width, rays, times, occluded);
            std::size_t bad = 0, bad_occluded = 0;
            for (std::size_t i = 0; i < rays.size(); ++i) {
                if (!same_closest_hit(want[i], got[i]) && ++bad <= 3)
                    ADD_FAILURE() << kind << " width " << width << " ray " << i << " at time " << times[i] << ": "
                                  << describe(rays[i]) << "\n  brute " << describe(want[i]) << ", got "
                                  << describe(got[i]);
                bad_occluded += occluded[i] != want_occluded[i];
                // Occlusion is the closest hit's existence.
                EXPECT_EQ(want_occluded[i] != 0, want[i].found()) << "ray " << i;
            }
            EXPECT_EQ(bad, 0u) << kind << " width " << width;
            EXPECT_EQ(bad_occluded, 0u) << kind << " width " << width;
        }
    }
}

/// At the shutter's opening the moving scene is the scene without its
/// `move` lines bit for bit (the placements are the identity there); at
/// its closing, the scene written where everything has moved to, up to the
/// rounding of the ray's trip to object space.
TEST(Motion, AtTheShuttersEndsTheSceneIsItsStaticCopies) {
    const Scene moving = parse(moving_scene_text(3, 0.0f, 2.0f));
    const Scene start = parse(moving_scene_text(3, 0.0f, 2.0f, true));
    const Scene end = parse(moving_scene_text(3, 0.0f, 2.0f, false, true));
    std::mt19937 rng(5);
    std::vector<Rayf> rays = camera_rays(moving, 48);
    for (const Rayf& r : random_rays(moving, rng, 2000, 0.2f)) rays.push_back(r);
    const auto accel = build_accel(moving, accel_config("bvh4"));
    for (const bool at_end : {false, true}) {
        const Scene& copy = at_end ? end : start;
        const auto copy_accel = build_accel(copy, accel_config("bvh4"));
        std::vector<Hitf> want(rays.size()), got(rays.size());
        copy_accel->intersect_packets(1, rays, want);
        const std::vector<float> times(rays.size(), at_end ? 2.0f : 0.0f);
        accel->intersect_at(1, rays, times, got);
        std::size_t hits = 0, bad = 0, grazing = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            hits += want[i].found();
            if (want[i].found() != got[i].found()) {
                ++grazing;
                continue;
            }
            if (!want[i].found()) continue;
            const bool same = at_end ? std::fabs(want[i].t - got[i].t) <= 1e-4f * want[i].t : want[i].t == got[i].t;
            if (!same && ++bad <= 3)
                ADD_FAILURE() << (at_end ? "end" : "start") << " ray " << i << ": copy " << describe(want[i])
                              << ", moving " << describe(got[i]);
            // The surface seen at that time is the copy's.
            const Surface a = surface_at(copy, rays[i], want[i]);
            const Surface b = surface_at(moving, rays[i], got[i], times[i]);
            EXPECT_LT(length(a.geometric_normal - b.geometric_normal), at_end ? 2e-3f : 1e-6f) << "ray " << i;
            EXPECT_EQ(copy.materials[a.material].color, moving.materials[b.material].color);
            const Vec3f pa = accurate_hit_point(copy, rays[i], want[i]);
            const Vec3f pb = accurate_hit_point(moving, rays[i], got[i], times[i]);
            EXPECT_LT(length(pa - pb), 1e-4f * (1.0f + length(pa))) << "ray " << i;
        }
        EXPECT_GT(hits, rays.size() / 4);
        EXPECT_EQ(bad, 0u);
        // Hit or miss differs only for rays grazing an edge at the closing.
        EXPECT_LE(grazing, at_end ? rays.size() / 1000 : 0u);
    }
}

/// A sphere moving along x: a ray along -z through its path hits it only
/// at the times it is there, with the normal of the sphere where it is.
TEST(Motion, ASphereIsWhereItIsAtTheRaysTime) {
    const Scene s = parse("shutter 0 10\nf 1 1 1 1 0 0 0 1\nmove 10 0 0\ns 0 0 0 1\n");
    const auto accel = build_accel(s, accel_config("bvh2"));
    const Rayf ray{{5, 0.5f, 10}, {0, 0, -1}};
    for (int k = 0; k <= 20; ++k) {
        const float time = 0.5f * float(k);  // the centre is at x = time
        const Hitf hit = [&] {
            Hitf h;
            accel->intersect_at(1, {&ray, 1}, {&time, 1}, {&h, 1});
            return h;
        }();
        const float dx = 5.0f - time, r2 = 1.0f - dx * dx - 0.25f;
        ASSERT_EQ(hit.found(), r2 > 0) << "time " << time;
        if (!hit.found()) continue;
        EXPECT_NEAR(hit.t, 10.0f - std::sqrt(r2), 1e-5f) << "time " << time;
        const Surface surf = surface_at(s, ray, hit, time);
        const Vec3f p = ray.org + ray.dir * hit.t;
        const Vec3f n = normalize(p - Vec3f{time, 0, 0});
        EXPECT_LT(length(surf.geometric_normal - n), 1e-5f) << "time " << time;
    }
}

/// A shutter of no length freezes the motion at its opening: distribution
/// and path-traced renders of the moving scene are those of the scene
/// without its `move` lines (up to the rounding of normals renormalised on
/// their way out of a placement).
TEST(Motion, AFrozenShutterRendersTheStaticScene) {
    std::string text = moving_scene_text(9, 0.0f, 0.0f);
    const Scene frozen = parse(text);
    ASSERT_FALSE(frozen.moving_instances.empty());
    const Scene still = parse(moving_scene_text(9, 0.0f, 0.0f, true));
    const auto a = build_accel(frozen, accel_config("bvh4"));
    const auto b = build_accel(still, accel_config("bvh4"));
    WhittedOptions o;
    o.width = o.height = 32;
    o.distribution = true;
    o.spp = 4;
    Image ia, ib;
    render_whitted(frozen, *a, o, ia);
    render_whitted(still, *b, o, ib);
    double diff = 0;
    for (std::size_t i = 0; i < ia.rgb.size(); ++i) diff = std::max(diff, double(std::fabs(ia.rgb[i] - ib.rgb[i])));
    EXPECT_LT(diff, 1e-3);
    PathOptions path;
    render_path(frozen, *a, o, path, ia);
    render_path(still, *b, o, path, ib);
    double sum = 0;
    for (std::size_t i = 0; i < ia.rgb.size(); ++i) sum += std::fabs(ia.rgb[i] - ib.rgb[i]);
    EXPECT_LT(sum / double(ia.rgb.size()), 1e-3);
    // And the moving scene over a real shutter renders otherwise.
    const Scene moving = parse(moving_scene_text(9, 0.0f, 1.0f));
    render_whitted(moving, *build_accel(moving, accel_config("bvh4")), o, ia);
    render_whitted(still, *b, o, ib);
    diff = 0;
    for (std::size_t i = 0; i < ia.rgb.size(); ++i) diff = std::max(diff, double(std::fabs(ia.rgb[i] - ib.rgb[i])));
    EXPECT_GT(diff, 0.05);
}

/// Distribution ray tracing of a moving scene converges to the average of
/// the static scene over the shutter: the mean of renders of static copies
/// at 32 times agrees with a 1024-sample motion render, and the error of
/// renders with few samples falls as 1 / sqrt(spp).
TEST(Motion, BlurredRendersConvergeToTheTimeAverage) {
    const auto scene_at = [](float shift) {
        std::ostringstream t;
        t << "v from 0 -8 2 at 0 0 0 up 0 0 1 angle 40 hither 0.01 resolution 20 20\n"
             "l 3 -6 6\nb 0.1 0.1 0.2\nf 0.7 0.7 0.7 1 0 0 0 1\np 4 -5 -5 -1 5 -5 -1 5 5 -1 -5 5 -1\n"
             "f 1 0.3 0.2 0.9 0 0 0 1\n";
        if (shift < 0) t << "move 3 0 1\ns -1.5 0 0 1\n";
        else t << "s " << -1.5f + 3 * shift << " 0 " << shift << " 1\n";
        return parse(t.str());
    };
    const Scene moving = scene_at(-1);
    const auto accel = build_accel(moving, accel_config("bvh4"));
    WhittedOptions o;
    o.width = o.height = 20;
    o.distribution = true;
    o.sampler = SamplerKind::Random;
    const auto render = [&](const Scene& s, const Accel& a, int spp, std::uint64_t seed) {
        o.spp = spp;
        o.seed = seed;
        Image image;
        render_whitted(s, a, o, image);
        return image;
    };
    const auto rmse = [](const Image& a, const Image& b) {
        double sum = 0;
        for (std::size_t i = 0; i < a.rgb.size(); ++i) sum += double(a.rgb[i] - b.rgb[i]) * (a.rgb[i] - b.rgb[i]);
        return std::sqrt(sum / double(a.rgb.size()));
    };
    const Image reference = render(moving, *accel, 1024, 99);
    // The time average: static copies at 32 evenly spaced times, 32 samples each.
    Image average = reference;
    std::fill(average.rgb.begin(), average.rgb.end(), 0.0f);
    for (int k = 0; k < 32; ++k) {
        const Scene copy = scene_at((float(k) + 0.5f) / 32.0f);
        const Image im = render(copy, *build_accel(copy, accel_config("bvh4")), 32, 7 + std::uint64_t(k));
        for (std::size_t i = 0; i < im.rgb.size(); ++i) average.rgb[i] += im.rgb[i] / 32.0f;
    }
    const Image frozen = render(scene_at(0.0f), *build_accel(scene_at(0.0f), accel_config("bvh4")), 64, 3);
    const double blur = rmse(frozen, reference), agreement = rmse(average, reference);
    EXPECT_GT(blur, 0.05) << "the motion should blur the image";
    EXPECT_LT(agreement, blur / 8) << "the blurred render is the time average";
    std::vector<double> errors;
    for (const int spp : {4, 16, 64}) {
        double e = 0;
        for (std::uint64_t seed = 1; seed <= 4; ++seed) e += rmse(render(moving, *accel, spp, seed), reference) / 4;
        errors.push_back(e);
    }
    // Each 4x more samples halve the error (1 / sqrt(spp)), within noise.
    for (std::size_t k = 1; k < errors.size(); ++k) {
        const double ratio = errors[k - 1] / errors[k];
        EXPECT_GT(ratio, 1.6) << "spp step " << k;
        EXPECT_LT(ratio, 2.5) << "spp step " << k;
    }
}

}  // namespace
}  // namespace raypack
