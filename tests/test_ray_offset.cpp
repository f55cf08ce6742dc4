// Secondary-ray origins (render/ray_offset.h): Waechter & Binder's robust
// offset leaves no self-intersection from scale 1e-4 to 1e6 and at a 1e6
// translation, and renders the same picture from scale 1e-6 to 1e6; a fixed
// epsilon fails at some scale, so the measures can fail.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

#include "accel/accel.h"
#include "measure/accuracy_measures.h"
#include "measure/closed_meshes.h"
#include "render/ray_offset.h"
#include "measure/ray_sets.h"
#include "measure/scale_invariance.h"
#include "scene/load.h"
#include "tests/test_paths.h"

namespace raypack {
namespace {

struct Placed {
    float scale, translation;
};
constexpr Placed kPlacements[] = {{1e-4f, 0}, {1e-2f, 0}, {1, 0}, {1e2f, 0}, {1e4f, 0}, {1e6f, 0}, {1, 1e6f}};

SelfIntersections self_intersections(const Placed& p, OffsetPolicy policy) {
    const ObjectScene scene = mixed_convex_scene(p.scale, Vec3f{p.translation, p.translation, p.translation});
    const auto accel = build_accel(scene.scene, AccelConfig{});
    return count_self_intersections(scene, *accel, policy, 96, 96);
}

TEST(RayOffset, RobustHasNoSelfIntersectionAtAnyScaleOrTranslation) {
    for (const Placed& p : kPlacements) {
        const SelfIntersections s = self_intersections(p, OffsetPolicy::Robust);
        EXPECT_GT(s.shadow_rays, 1000u) << "scale " << p.scale << " translation " << p.translation;
        EXPECT_GT(s.reflect_rays, 1000u);
        EXPECT_EQ(s.self(), 0u) << "scale " << p.scale << " translation " << p.translation << ": shadow "
                                << s.shadow_self << "/" << s.shadow_rays << ", reflect " << s.reflect_self << "/"
                                << s.reflect_rays;
    }
}

TEST(RayOffset, FixedEpsilonSelfIntersectsFarFromTheOrigin) {
    // 1e-4 is a few ULPs of 1e3: at scale 1e4 most rays find their own surface.
    EXPECT_EQ(self_intersections({1, 0}, OffsetPolicy::Epsilon).self(), 0u);
    const SelfIntersections far = self_intersections({1e4f, 0}, OffsetPolicy::Epsilon);
    EXPECT_GT(far.self(), far.rays() / 10);
}

TEST(RayOffset, RobustMovesEachCoordinate256UlpsTowardTheNormal) {
    const Vec3f p{1.0f, -2.0f, 1000.0f};
    const Vec3f moved = offset_ray_origin_robust(p, {1, 0, 0});
    EXPECT_EQ(std::bit_cast<std::int32_t>(moved.x) - std::bit_cast<std::int32_t>(p.x), 256);
    EXPECT_EQ(moved.y, p.y);
    EXPECT_EQ(moved.z, p.z);
    // Toward the normal whatever the signs of the coordinate and the normal.
    for (float x : {3.0f, -3.0f})
        for (float n : {1.0f, -1.0f}) {
            const Vec3f m = offset_ray_origin_robust({x, x, x}, {n, n, n});
            EXPECT_GT((m.x - x) * n, 0) << x << " " << n;
        }
    // Near zero ULPs are too small: 1/65536 along n instead.
    const Vec3f near_zero = offset_ray_origin_robust({1e-9f, 0, -0.01f}, {0, 0, 1});
    EXPECT_EQ(near_zero.x, 1e-9f);
    EXPECT_FLOAT_EQ(near_zero.z, -0.01f + 1.0f / 65536);
}

TEST(RayOffset, RobustNearOriginConstantsScaleWithTheSceneExtent) {
    // The chapter's 1/32 and 1/65536 hold for extent 1; at extent 1e-4 the
    // threshold and the offset shrink with it (issue 19).
    const Vec3f p{1e-7f, 0, 2e-6f};
    const Vec3f small = offset_ray_origin_robust(p, {0, 0, 1}, 1e-4f);
    EXPECT_EQ(small.x, p.x);
    EXPECT_FLOAT_EQ(small.z, 2e-6f + 1e-4f / 65536);
    // At 1e-4 / 32 and above: ULPs as everywhere else.
    const Vec3f above = offset_ray_origin_robust({0, 0, 1e-5f}, {0, 0, 1}, 1e-4f);
    EXPECT_EQ(std::bit_cast<std::int32_t>(above.z) - std::bit_cast<std::int32_t>(1e-5f), 256);
}

// The scene of balls.nff (spheres on a polygon) and of rings.nff (cones and
// spheres) at 96 x 96, robust offset: scaled by 1e-6 ... 1e6 the picture stays
// within 45 dB of the unscaled one (the measure at 256 x 256 is in
// docs/reliability.md; before the fix 1e-4 gave 21.9 dB on balls).
TEST(RayOffset, RobustRenderIsTheSameAtEveryScale) {
    for (const char* name : {"balls.nff", "rings.nff"}) {
        const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + name);
        for (float s : {1e-6f, 1e-4f, 1e-2f, 1e3f, 1e6f}) {
            const ImageError e = scale_invariance_error(scene, OffsetPolicy::Robust, s, Vec3f{}, 96, 96);
            EXPECT_GE(e.psnr_db, 45.0) << name << " scale " << s;
        }
    }
}

TEST(RayOffset, FixedEpsilonRenderChangesWithScale) {
    // The measure can fail: epsilon's absolute 1e-4 is a whole ball at 1e-4.
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/balls.nff");
    EXPECT_LT(scale_invariance_error(scene, OffsetPolicy::Epsilon, 1e-4f, Vec3f{}, 96, 96).psnr_db, 30.0);
}

TEST(RayOffset, NamesRoundTrip) {
    for (OffsetPolicy p : {OffsetPolicy::Epsilon, OffsetPolicy::Scaled, OffsetPolicy::Robust})
        EXPECT_EQ(parse_offset_policy(offset_policy_name(p)), p);
    EXPECT_FALSE(parse_offset_policy("tiny").has_value());
    EXPECT_EQ(offset_policy_list(), "epsilon|scaled|robust");
}

TEST(RayOffset, BarycentricHitPointLiesCloserToTheTriangle) {
    // Seen from 1e5 away, org + t dir rounds at the magnitude of org (ULP
    // 0.008); the barycentric point only at the magnitude of the vertices.
    Scene scene;
    scene.materials.push_back(Material{});
    const Vec3f base{10, -3, 7};
    scene.add_triangle(base + Vec3f{0, 0, 0}, base + Vec3f{10, 1, 0}, base + Vec3f{2, 9, 3}, 0);
    scene.update_features();
    const auto accel = build_accel(scene, AccelConfig{});
    const Vec3d a(scene.triangles.p0[0]), b(scene.triangles.p1[0]), c(scene.triangles.p2[0]);
    const Vec3d n = normalize(cross(b - a, c - a));
    double sum_bary = 0, sum_ray = 0;
    for (int i = 0; i < 200; ++i) {
        const float u = 0.1f + 0.003f * float(i), v = 0.2f;
        const Vec3f target = scene.triangles.p0[0] * (1 - u - v) + scene.triangles.p1[0] * u + scene.triangles.p2[0] * v;
        Rayf ray;
        ray.org = base + Vec3f{-3e4f, 2e4f, 9e4f + float(i)};
        ray.dir = target - ray.org;
        const Hitf hit = accel->intersect1(ray);
        ASSERT_TRUE(hit.found());
        sum_bary += std::fabs(dot(Vec3d(accurate_hit_point(scene, ray, hit)) - a, n));
        sum_ray += std::fabs(dot(Vec3d(ray.org + ray.dir * hit.t) - a, n));
    }
    EXPECT_LT(sum_bary * 100, sum_ray);
}

TEST(RayOffset, ShadowRaySetFollowsThePolicy) {
    const ObjectScene scene = mixed_convex_scene(1e4f, Vec3f{});
    const std::vector<Rayf> scaled = shadow_ray_set(scene.scene, 32, 32, OffsetPolicy::Scaled);
    const std::vector<Rayf> robust = shadow_ray_set(scene.scene, 32, 32, OffsetPolicy::Robust);
    ASSERT_EQ(scaled.size(), robust.size());
    ASSERT_FALSE(robust.empty());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < robust.size(); ++i) {
        EXPECT_EQ(robust[i].tnear, 0.0f);
        differ += !(scaled[i].org == robust[i].org);
    }
    EXPECT_GT(differ, robust.size() / 2);
}

// Scenes without a point light: the shadow set aims at the first distant
// light, else at the first area light (a parallelogram's centre), as
// `raypack rays --kind shadow` documents.
TEST(RayOffset, ShadowRaySetWithoutPointLights) {
    Scene cornell = load_scene("gen:cornell:1");
    ASSERT_TRUE(cornell.lights.empty());
    ASSERT_TRUE(cornell.distant_lights.empty());
    ASSERT_FALSE(cornell.area_lights.empty());
    const AreaLight& l = cornell.area_lights.front();
    ASSERT_EQ(l.shape, AreaLightShape::Parallelogram);
    const Vec3f centre = l.corner + l.edge1 * 0.5f + l.edge2 * 0.5f;
    const std::vector<Rayf> to_area = shadow_ray_set(cornell, 24, 24);
    ASSERT_FALSE(to_area.empty());
    for (const Rayf& r : to_area) {
        EXPECT_EQ(r.tfar, kShadowRayEnd);
        const Vec3f end = r.org + r.dir;
        EXPECT_NEAR(length(end - centre), 0.0f, 1e-4f * length(l.edge1));
    }
    // A distant light takes precedence over the area light.
    DistantLight sun;
    sun.direction = normalize(Vec3f{-1, -2, -3});
    cornell.distant_lights.push_back(sun);
    const std::vector<Rayf> to_sun = shadow_ray_set(cornell, 24, 24);
    ASSERT_EQ(to_sun.size(), to_area.size());
    for (const Rayf& r : to_sun) {
        EXPECT_EQ(r.tfar, std::numeric_limits<float>::infinity());
        EXPECT_EQ(r.dir, -sun.direction);
    }
}

}  // namespace
}  // namespace raypack
