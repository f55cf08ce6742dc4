// Every structure and kernel where floating point is at its worst: scenes
// scaled from 1e-8 to 1e8 and moved far from the origin, axis-parallel rays
// with signed zeros starting on primitive bounding planes, grazing rays,
// degenerate triangles, zero-radius and huge spheres, rays that start inside
// objects, tnear == tfar. The answers are analytic where they can be and the
// brute-force oracle's otherwise.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "oracle_harness.h"
#include "render/whitted.h"
#include "scene/scene.h"

namespace raypack {
namespace {

using oracle_harness::describe;

/// The structures under test: every kind but the oracle itself and Embree
/// (which has its own agreement test).
std::vector<std::string> structures() {
    std::vector<std::string> out;
    for (const char* k : accel_kinds())
        if (std::string(k) != "brute" && !is_embree_kind(k)) out.push_back(k);
    return out;
}

/// A closed UV-sphere mesh: vertices computed once and shared, so that
/// neighbouring triangles meet on exactly the same edges.
void add_mesh_sphere(Scene& scene, const Vec3f& centre, float radius, int segments, int rings) {
    std::vector<Vec3f> v;
    const double pi = 3.14159265358979323846;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const double th = pi * r / rings, ph = 2 * pi * s / segments;
            v.push_back(centre + Vec3f{float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                                       float(std::sin(th) * std::sin(ph))} *
                                     radius);
        }
    auto at = [&](int r, int s) { return v[std::size_t(r * segments + (s % segments))]; };
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            if (r != 0) scene.add_triangle(at(r, s), at(r, s + 1), at(r + 1, s), 0);
            if (r != rings - 1) scene.add_triangle(at(r, s + 1), at(r + 1, s + 1), at(r + 1, s), 0);
        }
}

/// Spheres, a cone, a closed mesh, a floor and two degenerate triangles,
/// all of size ~`scale` around `offset`.
Scene extreme_scene(float scale, const Vec3f& offset) {
    Scene scene;
    scene.materials.push_back(Material{});
    auto p = [&](float x, float y, float z) { return offset + Vec3f{x, y, z} * scale; };
    add_mesh_sphere(scene, p(0, 0, 0), scale, 12, 8);
    scene.add_sphere(p(3, 0, 0), 0.5f * scale, 0);
    scene.add_cone(p(-3, -0.5f, 0), 0.4f * scale, p(-3, 0.5f, 0), 0.1f * scale, 0);
    scene.add_triangle(p(-6, -2, -6), p(6, -2, -6), p(6, -2, 6), 0);
    scene.add_triangle(p(-6, -2, -6), p(6, -2, 6), p(-6, -2, 6), 0);
    scene.add_triangle(p(0, 3, 0), p(0, 3, 0), p(0, 3, 0), 0);   // a point
    scene.add_triangle(p(0, 3, 1), p(1, 3, 1), p(2, 3, 1), 0);   // collinear
    scene.lights.push_back(PointLight{p(2, 8, 5)});
    scene.camera.from = p(0, 1, 8);
    scene.camera.at = p(0, 0, 0);
    scene.has_camera = true;
    scene.update_features();
    return scene;
}

/// Rays aimed at interior points of every non-degenerate primitive, random
/// rays, and axis-parallel rays (both signs of zero in the other components)
/// starting on the bounding planes of every primitive.
std::vector<Rayf> extreme_rays(const Scene& scene, float scale, const Vec3f& offset) {
    std::vector<Rayf> rays;
    const Vec3f eye = offset + Vec3f{0.3f, 1.7f, 8.0f} * scale;
    auto aim = [&](const Vec3f& target) {
        Rayf r;
        r.org = eye;
        r.dir = target - eye;
        r.tnear = 0;
        r.tfar = std::numeric_limits<float>::infinity();
        rays.push_back(r);
    };
    const TriangleSoA& t = scene.triangles;
    for (std::size_t i = 0; i < t.size(); ++i) {
        const Vec3f a = t.p0[i], b = t.p1[i], c = t.p2[i];
        aim((a + b + c) * (1.0f / 3.0f));
    }
    aim(offset + Vec3f{3, 0, 0} * scale);
    aim(offset + Vec3f{-3, 0, 0} * scale);
    std::mt19937 rng(11);
    const Box3f box = oracle_harness::grown(scene_bounds(scene), 0.2f);
    for (int i = 0; i < 400; ++i) {
        Rayf r;
        r.org = oracle_harness::random_point(rng, box);
        r.dir = oracle_harness::random_direction(rng);
        r.tnear = 0;
        r.tfar = std::numeric_limits<float>::infinity();
        rays.push_back(r);
    }
    for (std::uint32_t prim = 0; prim < scene.primitive_count(); prim += 3) {
        const Box3f b = primitive_bounds(scene, prim);
        const Vec3f mid = (b.lo + b.hi) * 0.5f;
        for (int axis = 0; axis < 3; ++axis)
            for (int sign = 0; sign < 2; ++sign) {
                Rayf r;
                float d[3] = {oracle_harness::signed_zero(rng), oracle_harness::signed_zero(rng),
                              oracle_harness::signed_zero(rng)};
                d[axis] = sign ? -1.0f : 1.0f;
                r.dir = {d[0], d[1], d[2]};
                // Start outside the box along the axis, on its lo/hi planes across it.
                float o[3] = {mid.x, mid.y, mid.z};
                const float lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
                o[axis] = sign ? hi[axis] + 4 * scale : lo[axis] - 4 * scale;
                const int u = (axis + 1) % 3, v = (axis + 2) % 3;
                for (float ou : {lo[u], mid[u], hi[u]})
                    for (float ov : {lo[v], hi[v]}) {
                        o[u] = ou, o[v] = ov;
                        r.org = {o[0], o[1], o[2]};
                        r.tnear = 0;
                        r.tfar = std::numeric_limits<float>::infinity();
                        rays.push_back(r);
                    }
            }
    }
    return rays;
}

bool same_answer(const Hitf& want, const Hitf& got) {
    if (want.found() != got.found()) return false;
    return !want.found() || std::abs(got.t - want.t) <= 1e-5f * std::abs(want.t);
}

/// Closest hit and occlusion of `accel` at packet widths 1 and 8 against the oracle.
void expect_agreement(const Scene& scene, const std::string& kind, const std::vector<Rayf>& rays,
                      const std::string& where, KernelChoice kernels = {}) {
    const BruteForce oracle(scene, kernels);
    std::vector<Hitf> want(rays.size());
    std::vector<std::uint8_t> want_occ(rays.size());
    oracle.intersect(rays, want);
    oracle.occluded(rays, want_occ);
    AccelConfig config;
    config.kind = kind;
    config.kernels = kernels;
    const auto accel = build_accel(scene, config);
    for (int width : {1, 8}) {
        if (width != 1 && !accel->supports_packet(width)) continue;
        std::vector<Hitf> got(rays.size());
        std::vector<std::uint8_t> got_occ(rays.size());
        accel->intersect_packets(width, rays, got);
        accel->occluded_packets(width, rays, got_occ);
        int reported = 0;
        for (std::size_t i = 0; i < rays.size() && reported < 5; ++i) {
            const bool ok = same_answer(want[i], got[i]) && want_occ[i] == got_occ[i];
            if (!ok) ++reported;
            EXPECT_TRUE(ok) << where << " " << kind << " K=" << width << " ray " << i << ": " << describe(rays[i])
                            << "\n  oracle " << describe(want[i]) << " occluded " << int(want_occ[i]) << ", got "
                            << describe(got[i]) << " occluded " << int(got_occ[i]);
        }
    }
}

struct Placement {
    float scale;
    float offset;
};

class ExtremeScale : public ::testing::TestWithParam<Placement> {};

TEST_P(ExtremeScale, EveryStructureAgreesWithTheOracle) {
    const auto [scale, off] = GetParam();
    const Vec3f offset{off, -0.5f * off, 0.25f * off};
    const Scene scene = extreme_scene(scale, offset);
    const std::vector<Rayf> rays = extreme_rays(scene, scale, offset);
    // Analytic: the rays aimed at interior points of the mesh, sphere and cone
    // hit something, through the watertight test (Moeller-Trumbore may let a
    // ray through a shared edge). Only around the origin: far from it the
    // vertices and the aimed-at centroids snap to a coarse float grid, and a
    // centroid near the silhouette may round to a point off the mesh.
    KernelChoice watertight;
    watertight.triangle = TriangleMethod::Watertight;
    const BruteForce oracle(scene, watertight);
    const std::size_t aimed = off == 0 ? scene.triangles.size() + 2 : 0;
    for (std::size_t i = 0; i < aimed; ++i) {
        const bool degenerate = i == scene.triangles.size() - 2 || i == scene.triangles.size() - 1;
        if (degenerate) continue;
        EXPECT_TRUE(oracle.intersect1(rays[i]).found()) << "aimed ray " << i << " of " << aimed << " " << describe(rays[i]);
    }
    const std::string where = "scale " + std::to_string(scale) + " offset " + std::to_string(off);
    for (const std::string& kind : structures()) {
        expect_agreement(scene, kind, rays, where);
        expect_agreement(scene, kind, rays, where + " watertight", watertight);
    }
}

INSTANTIATE_TEST_SUITE_P(Placements, ExtremeScale,
                         ::testing::Values(Placement{1e-8f, 0}, Placement{1e-4f, 0}, Placement{1, 0},
                                           Placement{1e4f, 0}, Placement{1e7f, 0}, Placement{1, 1e6f},
                                           Placement{1e-3f, 1e3f}, Placement{1e2f, 1e8f}),
                         [](const ::testing::TestParamInfo<Placement>& placement) {
                             return "case" + std::to_string(placement.index);
                         });

/// A ray in the plane of a triangle sees no area: a miss for every triangle
/// test and structure, and never a NaN distance.
TEST(Extremes, GrazingRaysInATrianglePlaneMiss) {
    Scene scene;
    scene.materials.push_back(Material{});
    scene.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
    scene.update_features();
    std::vector<Rayf> rays;
    for (float y : {0.0f, 0.25f, 0.5f, 1.0f})
        for (float dy : {0.0f, 0.3f, -0.2f}) {
            Rayf r;
            r.org = {-1, y, 0};
            r.dir = {1, dy, 0};
            rays.push_back(r);
            r.org = {-1, y, -0.0f};
            r.dir = {1, dy, -0.0f};
            rays.push_back(r);
        }
    for (TriangleMethod m : {TriangleMethod::Moeller, TriangleMethod::Watertight, TriangleMethod::Plane}) {
        KernelChoice k;
        k.triangle = m;
        const BruteForce oracle(scene, k);
        for (const Rayf& r : rays) {
            const Hitf h = oracle.intersect1(r);
            EXPECT_FALSE(h.found()) << int(m) << " " << describe(r) << " -> " << describe(h);
        }
    }
    for (const std::string& kind : structures()) expect_agreement(scene, kind, rays, "grazing");
}

/// Zero-area and collinear triangles are never hit by any test, and every
/// structure builds over them.
TEST(Extremes, DegenerateTrianglesAreNeverHit) {
    Scene scene;
    scene.materials.push_back(Material{});
    scene.add_triangle({1, 1, 0}, {1, 1, 0}, {1, 1, 0}, 0);
    scene.add_triangle({0, 0, 0}, {1, 1, 0}, {2, 2, 0}, 0);
    scene.add_triangle({0, 0, 0}, {0, 0, 0}, {2, 2, 0}, 0);
    scene.update_features();
    std::vector<Rayf> rays;
    for (float x : {0.0f, 0.5f, 1.0f, 1.5f, 2.0f}) {
        Rayf r;
        r.org = {x, x, 5};
        r.dir = {0, 0, -1};
        rays.push_back(r);
        r.dir = {-0.0f, 0.0f, -1};
        rays.push_back(r);
    }
    for (TriangleMethod m : {TriangleMethod::Moeller, TriangleMethod::Watertight, TriangleMethod::Plane}) {
        KernelChoice k;
        k.triangle = m;
        const BruteForce oracle(scene, k);
        for (const Rayf& r : rays) EXPECT_FALSE(oracle.intersect1(r).found()) << int(m) << " " << describe(r);
    }
    for (const std::string& kind : structures()) expect_agreement(scene, kind, rays, "degenerate");
}

/// A zero-radius sphere is a point and never hit (the kernels' convention, as
/// for degenerate triangles), even by a ray through it or passing it at 1e-30.
/// A sphere of radius 1e7 is hit from inside and outside at the analytic
/// distance by every sphere test (relative error within the stated bound).
TEST(Extremes, ZeroRadiusAndHugeSpheres) {
    Scene tiny;
    tiny.materials.push_back(Material{});
    tiny.add_sphere({0, 0, 0}, 0.0f, 0);
    tiny.update_features();
    Scene huge;
    huge.materials.push_back(Material{});
    huge.add_sphere({0, 0, 0}, 1e7f, 0);
    huge.update_features();
    for (SphereMethod m : {SphereMethod::Algebraic, SphereMethod::Geometric, SphereMethod::Precise}) {
        KernelChoice k;
        k.sphere = m;
        const BruteForce point(tiny, k), big(huge, k);
        Rayf through;
        through.org = {0.5f, 0, 0};
        through.dir = {-1, 0, 0};
        EXPECT_FALSE(point.intersect1(through).found()) << int(m);
        Rayf inside;
        inside.org = {1, 2, 3};
        inside.dir = {0, 0, 1};
        const Hitf hi = big.intersect1(inside);
        ASSERT_TRUE(hi.found()) << int(m);
        const double exact = std::sqrt(1e14 - 5.0) - 3.0;
        EXPECT_NEAR(hi.t, exact, 1e-5 * exact) << int(m);
        Rayf outside;
        outside.org = {0, 0, -3e7f};
        outside.dir = {0, 0, 1};
        const Hitf ho = big.intersect1(outside);
        ASSERT_TRUE(ho.found()) << int(m);
        EXPECT_NEAR(ho.t, 2e7, 2e7 * 1e-5) << int(m);
    }
    std::vector<Rayf> rays;
    for (float x : {0.0f, -0.0f, 1e-30f}) {
        Rayf r;
        r.org = {x, 0, 5};
        r.dir = {0, 0, -1};
        rays.push_back(r);
    }
    for (const std::string& kind : structures()) expect_agreement(tiny, kind, rays, "zero radius");
}

/// From inside a sphere or a closed mesh, a ray leaves through exactly one
/// surface point: every structure finds it.
TEST(Extremes, RaysStartingInsideObjects) {
    Scene scene;
    scene.materials.push_back(Material{});
    add_mesh_sphere(scene, {0, 0, 0}, 1, 16, 10);
    scene.add_sphere({5, 0, 0}, 1, 0);
    scene.update_features();
    std::mt19937 rng(5);
    std::vector<Rayf> rays;
    for (int i = 0; i < 300; ++i) {
        Rayf r;
        r.org = i % 2 ? Vec3f{0.1f, -0.2f, 0.05f} : Vec3f{5.2f, 0.1f, -0.3f};
        r.dir = oracle_harness::random_direction(rng);
        rays.push_back(r);
    }
    const BruteForce oracle(scene, KernelChoice{});
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hitf h = oracle.intersect1(rays[i]);
        ASSERT_TRUE(h.found()) << describe(rays[i]);
        if (i % 2 == 0) {  // the analytic sphere: |org + t dir - c| = 1
            const Vec3f p = rays[i].org + rays[i].dir * h.t - Vec3f{5, 0, 0};
            EXPECT_NEAR(std::sqrt(dot(p, p)), 1.0f, 1e-5f) << describe(rays[i]);
        }
    }
    for (const std::string& kind : structures()) expect_agreement(scene, kind, rays, "inside");
}

/// tnear == tfar: a hit exactly there counts (the interval is closed), any
/// other distance does not; every structure agrees with the oracle. With the
/// watertight test: Moeller-Trumbore may report a hit a rounding outside its
/// triangle, hence outside the box a structure culls by, which only a ray
/// confined to that one distance notices.
TEST(Extremes, EmptyIntervalTnearEqualsTfar) {
    const Scene scene = extreme_scene(1, {0, 0, 0});
    KernelChoice watertight;
    watertight.triangle = TriangleMethod::Watertight;
    const BruteForce oracle(scene, watertight);
    std::vector<Rayf> rays = extreme_rays(scene, 1, {0, 0, 0});
    std::vector<Rayf> pinned;
    for (const Rayf& r : rays) {
        const Hitf h = oracle.intersect1(r);
        if (!h.found()) continue;
        Rayf at = r;
        at.tnear = at.tfar = h.t;
        pinned.push_back(at);
        Rayf before = r;
        before.tnear = before.tfar = h.t * 0.5f;
        pinned.push_back(before);
    }
    ASSERT_GT(pinned.size(), 100u);
    for (std::size_t i = 0; i < pinned.size(); i += 2) {
        EXPECT_TRUE(oracle.intersect1(pinned[i]).found()) << describe(pinned[i]);
    }
    for (const std::string& kind : structures()) expect_agreement(scene, kind, pinned, "tnear == tfar", watertight);
}

/// No NaN or infinity reaches an image, at any scale and far from the origin.
TEST(Extremes, NoNaNReachesTheImage) {
    for (const Placement& pl : {Placement{1e-6f, 0}, Placement{1e6f, 0}, Placement{1, 1e6f}}) {
        const Scene scene = extreme_scene(pl.scale, Vec3f{pl.offset, pl.offset, pl.offset});
        AccelConfig config;
        const auto accel = build_accel(scene, config);
        WhittedOptions options;
        options.width = options.height = 48;
        Image image(options.width, options.height);
        render_whitted(scene, *accel, options, image);
        int lit = 0;
        for (float c : image.rgb) {
            ASSERT_TRUE(std::isfinite(c)) << "scale " << pl.scale << " offset " << pl.offset;
            lit += c > 0;
        }
        EXPECT_GT(lit, 100) << "scale " << pl.scale << " offset " << pl.offset;
    }
}

}  // namespace
}  // namespace raypack
