// Instancing (NFF begin/end/inst, accel/prims/instance_prims.h): every
// structure and packet width against the same scene flattened, surfaces and
// normals against the flattened ones, an ellipsoid's analytic normal, the
// identity placement bit for bit, nested placements, and the errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "oracle_harness.h"
#include "scene_errors.h"
#include "render/image.h"
#include "render/surface.h"
#include "render/whitted.h"
#include "scene/flatten_instances.h"
#include "scene/load.h"
#include "scene/nff_text.h"

namespace raypack {
namespace {

using namespace oracle_harness;

Scene parse(const std::string& text) { return load_nff_text(text, "test.nff"); }

/// "m00 .. m23" of a random rotation (a random unit quaternion), uniform
/// scale in [0.3, 1.2] and translation in [-3, 3]^3.
std::string random_similarity(std::mt19937& rng) {
    std::normal_distribution<double> n;
    std::uniform_real_distribution<double> scale(0.3, 1.2), shift(-3, 3);
    double q[4];
    double len = 0;
    for (double& c : q) c = n(rng), len += c * c;
    for (double& c : q) c /= std::sqrt(len);
    const double w = q[0], x = q[1], y = q[2], z = q[3], s = scale(rng);
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                            {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                            {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    std::ostringstream out;
    out.precision(9);
    for (int i = 0; i < 3; ++i) out << s * r[i][0] << ' ' << s * r[i][1] << ' ' << s * r[i][2] << ' ' << shift(rng) << ' ';
    return out.str();
}

/// Two objects, the second placing the first (so two levels of instances),
/// placed many times among primitives of the scene's own; triangles with
/// and without vertex normals, spheres, a mirrored placement.
std::string nested_scene_text(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1);
    std::ostringstream t;
    t << "v from 0 -12 4 at 0 0 0 up 0 0 1 angle 50 hither 0.01 resolution 64 64\n";
    t << "l 5 -5 8\nf 0.8 0.4 0.3 0.7 0.3 20 0 1\n";
    t << "begin leaf\n";
    for (int i = 0; i < 12; ++i) {
        t << "p 3";
        for (int k = 0; k < 9; ++k) t << ' ' << u(rng);
        t << '\n';
    }
    t << "pp 3 -1 -1 0 0 0 1  1 -1 0 0 0.3 1  0 1 0.5 0.2 0 1\n";
    for (int i = 0; i < 3; ++i) t << "s " << u(rng) << ' ' << u(rng) << ' ' << u(rng) << ' ' << 0.3f + 0.2f * u(rng) << '\n';
    t << "end\nf 0.3 0.8 0.3 0.7 0.3 20 0 1\nbegin group\n";
    for (int i = 0; i < 5; ++i) t << "inst leaf " << random_similarity(rng) << '\n';
    t << "s 0 0 0 0.4\nend\n";
    for (int i = 0; i < 4; ++i) t << "inst group " << random_similarity(rng) << '\n';
    t << "s 1 1 1 0.5\n";
    for (int i = 0; i < 6; ++i) t << "inst leaf " << random_similarity(rng) << '\n';
    t << "inst leaf -1 0 0 4  0 1 0 -4  0 0 1 0\n";  // a mirror
    t << "p 4 -8 -8 -3 8 -8 -3 8 8 -3 -8 8 -3\n";
    return t.str();
}

struct Compared {
    std::size_t rays = 0, hits = 0, disagree = 0;
    std::string first;
};

/// Instanced hits against the flattened scene's (brute force), through the
/// id map: the same primitive at t within `rel` (the transform's rounding
/// moves the surface by a few ULPs), or a miss on both.
Compared compare_to_flat(const std::vector<Rayf>& rays, const std::vector<Hitf>& flat,
                         const std::vector<std::uint32_t>& flat_to_id, const std::vector<Hitf>& got, float rel) {
    Compared c;
    c.rays = rays.size();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hitf& f = flat[i];
        bool same = f.found() == got[i].found();
        if (same && f.found()) {
            c.hits++;
            same = flat_to_id[f.prim] == got[i].prim && std::fabs(f.t - got[i].t) <= rel * f.t;
        }
        if (same) continue;
        if (++c.disagree <= 3)
            c.first += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    flat " + describe(f) +
                       " (id " + std::to_string(f.found() ? flat_to_id[f.prim] : kNoPrim) + "), instanced " +
                       describe(got[i]);
    }
    return c;
}

TEST(Instancing, NestedInstancesGiveTheFlattenedScenesHits) {
    const Scene scene = parse(nested_scene_text(3));
    ASSERT_TRUE(scene.features.instances);
    ASSERT_EQ(scene.objects.size(), 2u);
    // The floor (2 triangles) and a sphere; 4 groups of 5 leaves and a
    // sphere; 7 leaves placed directly; a leaf is 16 primitives.
    EXPECT_EQ(scene.instanced_primitive_count(), 2u + 1u + 4u * (5u * 16u + 1u) + 7u * 16u);
    std::vector<std::uint32_t> flat_to_id;
    const Scene flat = flatten_instances(scene, &flat_to_id);
    ASSERT_EQ(flat.primitive_count(), scene.instanced_primitive_count());
    const std::unique_ptr<Accel> flat_brute = build_accel(flat, accel_config("brute"));

    std::mt19937 rng(7);
    std::vector<Rayf> rays = camera_rays(scene, 64);
    for (const Rayf& r : random_rays(scene, rng, 4000, 0.2f)) rays.push_back(r);
    const std::vector<Hitf> want = trace_hits(*flat_brute, rays);
    const std::vector<Rayf> shadows = shadow_rays(flat, rays, want);
    const std::vector<std::uint8_t> want_occ = trace_occlusion(*flat_brute, shadows);

    for (const char* kind : {"brute", "bvh2", "bvh4", "bvh8", "grid", "kdtree", "octree"}) {
        const std::unique_ptr<Accel> accel = build_accel(scene, accel_config(kind));
        for (int width : {1, 4, 8, 16}) {
            if (width > 1 && !accel->supports_packet(width)) continue;
            const Compared c = compare_to_flat(rays, want, flat_to_id, trace_hits(*accel, rays, width), 2e-5f);
            EXPECT_GT(c.hits, rays.size() / 3) << kind;
            // Rays that graze an edge may land on the other side of it
            // after the transform's rounding: at most 1 in 1000.
            EXPECT_LE(c.disagree, c.rays / 1000) << kind << " width " << width << c.first;
            const std::vector<std::uint8_t> occ = trace_occlusion(*accel, shadows, width);
            std::size_t occ_disagree = 0;
            for (std::size_t i = 0; i < shadows.size(); ++i) occ_disagree += occ[i] != want_occ[i];
            EXPECT_LE(occ_disagree, shadows.size() / 1000) << kind << " width " << width << " shadows";
        }
    }
}

TEST(Instancing, SurfacesAreTheFlattenedScenesSurfaces) {
    const Scene scene = parse(nested_scene_text(5));
    std::vector<std::uint32_t> flat_to_id;
    const Scene flat = flatten_instances(scene, &flat_to_id);
    const std::unique_ptr<Accel> accel = build_accel(scene, accel_config("bvh4"));
    const std::unique_ptr<Accel> flat_accel = build_accel(flat, accel_config("bvh4"));
    const std::vector<Rayf> rays = camera_rays(scene, 64);
    const std::vector<Hitf> got = trace_hits(*accel, rays), want = trace_hits(*flat_accel, rays);
    const SurfaceTable table(scene), flat_table(flat);
    std::size_t compared = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!got[i].found() || !want[i].found() || flat_to_id[want[i].prim] != got[i].prim) continue;
        ++compared;
        const Surface a = table.at(rays[i], got[i]), b = flat_table.at(rays[i], want[i]);
        EXPECT_EQ(a.material, b.material) << i;
        EXPECT_LT(length(a.geometric_normal - b.geometric_normal), 1e-4f) << i;
        EXPECT_LT(length(a.shading_normal - b.shading_normal), 1e-4f) << i;
        EXPECT_LT(length(a.point - b.point), 1e-4f * length(b.point) + 1e-6f) << i;
    }
    EXPECT_GT(compared, rays.size() / 3);
}

TEST(Instancing, WhittedImageIsTheFlattenedScenes) {
    // Reflections, shadows and shading through placements (with a mirror and
    // vertex normals) against the same scene flattened: pixels apart only
    // where a ray grazes an edge that the transform's rounding moves.
    const Scene scene = parse(nested_scene_text(3));
    const Scene flat = flatten_instances(scene);
    WhittedOptions options;
    options.width = options.height = 96;
    Image a, b;
    const RenderStats sa = render_whitted(scene, *build_accel(scene, accel_config("bvh4")), options, a);
    const RenderStats sb = render_whitted(flat, *build_accel(flat, accel_config("bvh4")), options, b);
    EXPECT_GT(sa.eye_hits, 96u * 96u / 4);
    EXPECT_EQ(sa.eye_hits, sb.eye_hits);
    EXPECT_GT(sa.shadow_rays, 0u);
    EXPECT_GT(sa.reflect_rays, 0u);
    std::size_t apart = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) apart += std::fabs(a.rgb[i] - b.rgb[i]) > 1e-3f;
    EXPECT_LE(apart, a.rgb.size() / 200) << "channels differing by more than 1e-3";
}

TEST(Instancing, ScaledSphereIsAnEllipsoidWithItsAnalyticNormal) {
    // x^2/4 + y^2 + z^2 = 1.
    const Scene scene = parse("begin ball\ns 0 0 0 1\nend\ninst ball 2 0 0 0  0 1 0 0  0 0 1 0\n");
    const std::unique_ptr<Accel> accel = build_accel(scene, accel_config("bvh4"));
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-0.9f, 0.9f);
    for (int k = 0; k < 200; ++k) {
        // Straight down onto the ellipsoid at (x, y).
        const float x = 2 * u(rng), y = u(rng) * std::sqrt(1 - x * x / 4);
        const Rayf ray{{x, y, 5}, {0, 0, -1}};
        const Hitf hit = accel->intersect1(ray);
        ASSERT_TRUE(hit.found());
        const float z = std::sqrt(1 - x * x / 4 - y * y);
        EXPECT_NEAR(hit.t, 5 - z, 2e-5f);
        const Surface s = surface_at(scene, ray, hit);
        const Vec3f n = normalize(Vec3f{x / 4, y, z});  // the gradient
        EXPECT_LT(length(s.geometric_normal - n), 1e-4f) << x << ' ' << y;
    }
}

TEST(Instancing, IdentityPlacementIsThePrimitiveBitForBit) {
    const std::string leaf = "p 3 -1 -1 0.2  1 -0.7 0.1  0.1 1 -0.3\ns 0.3 0.2 0.1 0.6\n";
    const Scene direct = parse(leaf);
    const Scene placed = parse("begin o\n" + leaf + "end\ninst o 1 0 0 0  0 1 0 0  0 0 1 0\n");
    ASSERT_EQ(placed.hit_id_count(), 3u);  // the instance's own number, then the two inside
    std::mt19937 rng(2);
    const std::vector<Rayf> rays = random_rays(direct, rng, 2000, 0.5f);
    for (const char* kind : {"bvh2", "bvh8"}) {
        const std::vector<Hitf> a = trace_hits(*build_accel(direct, accel_config(kind)), rays, 8);
        const std::vector<Hitf> b = trace_hits(*build_accel(placed, accel_config(kind)), rays, 8);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            ASSERT_EQ(a[i].found(), b[i].found()) << i;
            if (!a[i].found()) continue;
            EXPECT_EQ(b[i].prim, a[i].prim + 1) << i;
            EXPECT_EQ(a[i].t, b[i].t) << i;
            EXPECT_EQ(a[i].u, b[i].u) << i;
            EXPECT_EQ(a[i].v, b[i].v) << i;
        }
    }
}

TEST(Instancing, HitIdsResolveToTheirPrimitive) {
    const Scene scene = parse(nested_scene_text(11));
    std::vector<std::uint32_t> flat_to_id;
    const Scene flat = flatten_instances(scene, &flat_to_id);
    ASSERT_EQ(flat_to_id.size(), flat.primitive_count());
    for (std::uint32_t p = 0; p < flat.primitive_count(); ++p) {
        const ResolvedHit r = resolve_hit_id(scene, flat_to_id[p]);
        ASSERT_LT(r.prim, r.scene->primitive_count());
        const PrimRef a = r.scene->prims[r.prim], b = flat.prims[p];
        ASSERT_EQ(a.kind, b.kind) << p;
        if (a.kind == PrimKind::Triangle) {
            const Vec3f q = r.to_world.point(r.scene->triangles.p0[a.index]);
            EXPECT_LT(length(q - flat.triangles.p0[b.index]), 1e-4f) << p;
        }
    }
}

TEST(Instancing, BadInputIsAClearError) {
    const BadScene cases[] = {
        {"s 0 0 0 1\ninst nothing 1 0 0 0 0 1 0 0 0 0 1 0\n", 2, "unknown object 'nothing'"},
        {"begin a\ns 0 0 0 1\nend\ninst a 1 0 0 0 0 1 0 0 0 0 0 0\n", 4, "singular instance matrix"},
        {"begin a\ns 0 0 0 1\nend\ninst a 1 0 0 0 0 1 0 0 0 0 1 nan\n", 4, "non-finite number 'nan'"},
        {"begin a\ns 0 0 0 1\nend\ninst a 1e-20 0 0 0 0 1e-20 0 0 0 0 1e-20 0\n", 4, "singular instance matrix"},
        {"begin a\ns 0 0 0 1\nend\ninst a 1 0 0\n", 4, "unexpected end of file"},
        {"begin a\ns 0 0 0 1\ninst a 1 0 0 0 0 1 0 0 0 0 1 0\nend\n", 3, "places itself"},
        {"end\n", 1, "'end' without 'begin'"},
        {"begin a\ns 0 0 0 1\n", 2, "begun on line 1 has no 'end'"},
        {"begin a\nbegin b\n", 2, "objects do not nest"},
        {"begin a\ns 0 0 0 1\nend\nbegin a\ns 0 0 0 1\nend\n", 4, "defined twice"},
        {"begin a\nl 0 0 1\nend\n", 2, "a light inside object 'a'"},
        {"begin a\nend\n", 2, "is empty"},
    };
    expect_scene_errors(cases);
}

TEST(Instancing, MoreHitIdsThan32BitsIsAClearError) {
    // 256^4 placements of a triangle: 2^32 hit ids.
    std::ostringstream t;
    t << "begin l0\np 3 0 0 0 1 0 0 0 1 0\nend\n";
    for (int level = 1; level <= 4; ++level) {
        t << "begin l" << level << '\n';
        for (int i = 0; i < 256; ++i) t << "inst l" << level - 1 << " 1 0 0 " << i << " 0 1 0 0 0 0 1 0\n";
        t << "end\n";
    }
    try {
        parse(t.str());
        ADD_FAILURE() << "accepted 2^32 instanced triangles";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("numbered in 32 bits"), std::string::npos) << e.what();
    }
}

TEST(Instancing, NestingDeeperThanTheLimitIsAClearError) {
    // A chain of objects, each placing the one before: one placement a level.
    auto chain = [](int levels) {
        std::string t = "begin o0\ns 0 0 0 1\nend\n";
        for (int i = 1; i <= levels; ++i)
            t += "begin o" + std::to_string(i) + "\ninst o" + std::to_string(i - 1) + " 1 0 0 0 0 1 0 0 0 0 1 0\nend\n";
        return t + "inst o" + std::to_string(levels) + " 1 0 0 0 0 1 0 0 0 0 1 0\n";
    };
    const Scene deepest = parse(chain(kMaxInstanceDepth - 1));
    EXPECT_EQ(deepest.instance_depth(), kMaxInstanceDepth);
    const std::unique_ptr<Accel> accel = build_accel(deepest, accel_config("bvh4"));
    const Hitf hit = accel->intersect1(Rayf{{0, 0, 5}, {0, 0, -1}});
    EXPECT_EQ(hit.t, 4.0f);
    EXPECT_EQ(resolve_hit_id(deepest, hit.prim).scene, deepest.objects[0].get());
    try {
        parse(chain(kMaxInstanceDepth));
        ADD_FAILURE() << "accepted " << kMaxInstanceDepth + 1 << " levels";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("levels deep"), std::string::npos) << e.what();
    }
}

TEST(Instancing, FlatteningRefusesWhatItCannotCopy) {
    const Scene scene = parse("begin b\ns 0 0 0 1\nend\ninst b 2 0 0 0  0 1 0 0  0 0 1 0\n");
    EXPECT_THROW(flatten_instances(scene), SceneError);
}

TEST(Instancing, EmbreeRefusesInstances) {
    const Scene scene = parse("begin b\ns 0 0 0 1\nend\ninst b 1 0 0 0  0 1 0 0  0 0 1 0\n");
    for (const char* kind : accel_kinds()) {
        if (!is_embree_kind(kind)) continue;
        EXPECT_THROW(build_accel(scene, accel_config(kind)), std::exception) << kind;
    }
}

TEST(Instancing, TetraInstancedIsTetrasPyramid) {
    for (int size : {3, 7, 10}) {
        const Scene placed = load_scene("gen:tetra-instanced:" + std::to_string(size));
        ASSERT_EQ(placed.instanced_primitive_count(), std::uint64_t(1) << (2 * size)) << size;
        if (size > 7) continue;
        // Flattened, the same triangles in the same order as tetra's (both
        // recurse the same way), up to the %g rounding of the printed numbers.
        const Scene flat = flatten_instances(placed), tetra = load_scene("gen:tetra:" + std::to_string(size));
        ASSERT_EQ(flat.triangles.size(), tetra.triangles.size());
        float worst = 0;
        for (std::size_t i = 0; i < flat.triangles.size(); ++i)
            for (auto p : {&TriangleSoA::p0, &TriangleSoA::p1, &TriangleSoA::p2}) {
                const Vec3f d = (flat.triangles.*p)[i] - (tetra.triangles.*p)[i];
                worst = std::max({worst, std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
            }
        EXPECT_LT(worst, 2e-5f) << size;
    }
}

}  // namespace
}  // namespace raypack
