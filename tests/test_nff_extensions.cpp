// raypack's NFF extensions (docs/scene-format.md): area, sphere and distant
// lights, OBJ meshes, a thin lens and glossy materials; and gen:cornell.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scene/load.h"
#include "tests/scene_files.h"
#include "tests/test_paths.h"

namespace {

using raypack::AreaLightShape;
using raypack::PrimKind;
using raypack::Scene;
using raypack::Vec3f;

constexpr const char* kView =
    "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.1\nresolution 64 32\n";  // lines 1-7

Vec3f triangle_normal(const Scene& s, std::uint32_t prim) {
    const std::uint32_t i = s.prims[prim].index;
    return cross(s.triangles.p1[i] - s.triangles.p0[i], s.triangles.p2[i] - s.triangles.p0[i]);
}

}  // namespace

class NffExtensions : public SceneFiles {
protected:
    NffExtensions() : SceneFiles(raypack::load_nff_file, ".nff") {}
};

TEST_F(NffExtensions, ParallelogramLightIsTwoTrianglesFacingItsEmittingSide) {
    const Scene s = load(std::string(kView) + "f 1 0 0 1 0 0 0 1\nla 0 2 0  1 0 0  0 0 1  1 0.5 0.25\ns 0 0 -5 1\n");
    ASSERT_EQ(s.area_lights.size(), 1u);
    const auto& l = s.area_lights[0];
    EXPECT_EQ(l.shape, AreaLightShape::Parallelogram);
    EXPECT_EQ(l.corner, (Vec3f{0, 2, 0}));
    EXPECT_EQ(l.edge1, (Vec3f{1, 0, 0}));
    EXPECT_EQ(l.edge2, (Vec3f{0, 0, 1}));
    EXPECT_TRUE(l.has_color);
    EXPECT_EQ(l.color, (Vec3f{1, 0.5f, 0.25f}));
    EXPECT_FLOAT_EQ(l.area(), 1.0f);
    ASSERT_EQ(l.prim_count, 2u);
    ASSERT_EQ(s.triangles.size(), 2u);
    // Objects after the light have the fill's material, not the light's surface.
    ASSERT_EQ(s.spheres.size(), 1u);
    EXPECT_EQ(s.materials[s.prim_material[2]].area_light, -1);
    EXPECT_EQ(s.materials[s.prim_material[2]].color, (Vec3f{1, 0, 0}));
    // e x f = (1,0,0) x (0,0,1) = (0,-1,0): both triangles face down.
    for (std::uint32_t p = l.first_prim; p < l.first_prim + 2; ++p) {
        EXPECT_EQ(s.prims[p].kind, PrimKind::Triangle);
        const Vec3f n = triangle_normal(s, p);
        EXPECT_LT(n.y, 0);
        EXPECT_EQ(n.x, 0);
        EXPECT_EQ(n.z, 0);
        const auto& m = s.materials[s.prim_material[p]];
        EXPECT_EQ(m.area_light, 0);
        EXPECT_EQ(m.color, (Vec3f{1, 0, 0}));  // the current material, marked as the light's
    }
    // The two triangles cover the parallelogram: their areas add up to |e x f|.
    EXPECT_FLOAT_EQ(0.5f * (length(triangle_normal(s, 0)) + length(triangle_normal(s, 1))), 1.0f);
    EXPECT_TRUE(s.features.area_lights);
    EXPECT_TRUE(s.features.colored_lights);
    EXPECT_EQ(s.light_count(), 1u);
}

TEST_F(NffExtensions, SphereAndDistantLights) {
    const Scene s = load(std::string(kView) + "ls 1 2 3 0.5\nld 0 -3 -4 0.2 0.3 0.4\nl 0 9 0\n");
    ASSERT_EQ(s.area_lights.size(), 1u);
    const auto& a = s.area_lights[0];
    EXPECT_EQ(a.shape, AreaLightShape::Sphere);
    EXPECT_EQ(a.center, (Vec3f{1, 2, 3}));
    EXPECT_EQ(a.radius, 0.5f);
    EXPECT_FALSE(a.has_color);
    EXPECT_FLOAT_EQ(a.area(), float(M_PI));
    ASSERT_EQ(a.prim_count, 1u);
    EXPECT_EQ(s.prims[a.first_prim].kind, PrimKind::Sphere);
    EXPECT_EQ(s.materials[s.prim_material[a.first_prim]].area_light, 0);
    ASSERT_EQ(s.distant_lights.size(), 1u);
    EXPECT_FLOAT_EQ(s.distant_lights[0].direction.y, -0.6f);  // normalised
    EXPECT_FLOAT_EQ(s.distant_lights[0].direction.z, -0.8f);
    EXPECT_EQ(s.distant_lights[0].color, (Vec3f{0.2f, 0.3f, 0.4f}));
    EXPECT_TRUE(s.features.distant_lights);
    // The SPD rule counts lights of every kind: L = 3 -> sqrt(3) / 6.
    EXPECT_EQ(s.light_count(), 3u);
    EXPECT_FLOAT_EQ(s.spd_light_intensity(), std::sqrt(3.0f) / 6.0f);
}

TEST_F(NffExtensions, ObjMeshTakesTheCurrentMaterialAndAPathRelativeToTheNffFile) {
    std::filesystem::create_directories(dir_ / "meshes");
    write("meshes/quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    const Scene s = load(std::string(kView) + "f 0 1 0 1 0 0 0 1\ns 0 0 -9 1\nf 0 0 1 1 0 0 0 1\nobj meshes/quad.obj\n");
    ASSERT_EQ(s.triangles.size(), 2u);
    ASSERT_EQ(s.primitive_count(), 3u);
    for (std::uint32_t p = 1; p < 3; ++p) EXPECT_EQ(s.materials[s.prim_material[p]].color, (Vec3f{0, 0, 1}));
    EXPECT_EQ(s.materials[s.prim_material[0]].color, (Vec3f{0, 1, 0}));
    // An absolute path works too, and a scene may use the same mesh twice.
    const Scene t = load(std::string(kView) + "obj " + (dir_ / "meshes/quad.obj").string() + "\nobj meshes/quad.obj\n");
    EXPECT_EQ(t.triangles.size(), 4u);
}

TEST_F(NffExtensions, LensAndGloss) {
    const Scene s = load(std::string(kView) + "lens 0.25 4.5\nf 1 1 1 1 0.5 10 0 1\ngloss 200\n"
                                              "f 1 1 1 1 0.5 10 0 1\ngloss 0\nf 1 1 1 1 0.5 10 0 1\n");
    EXPECT_EQ(s.camera.lens_radius, 0.25f);
    EXPECT_EQ(s.camera.focus_distance, 4.5f);
    EXPECT_TRUE(s.features.thin_lens);
    ASSERT_EQ(s.materials.size(), 3u);
    EXPECT_EQ(s.materials[0].gloss, 0.0f);  // gloss applies to the f lines after it
    EXPECT_EQ(s.materials[1].gloss, 200.0f);
    EXPECT_EQ(s.materials[2].gloss, 0.0f);  // gloss 0: the mirror again
    EXPECT_FALSE(s.features.glossy);        // no primitive uses the glossy material
    const Scene g = load(std::string(kView) + "gloss 8\nf 1 1 1 1 0.5 10 0 1\ns 0 0 0 1\n");
    EXPECT_TRUE(g.features.glossy);
    const Scene pinhole = load(kView);
    EXPECT_EQ(pinhole.camera.lens_radius, 0.0f);
    EXPECT_FALSE(pinhole.features.thin_lens);
}

TEST_F(NffExtensions, PlainSpdScenesUseNoExtension) {
    for (const char* name : {"balls", "gears", "mount", "rings", "teapot", "tetra", "tree"}) {
        const Scene s = raypack::load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + name + ".nff");
        EXPECT_TRUE(s.area_lights.empty() && s.distant_lights.empty()) << name;
        EXPECT_EQ(s.light_count(), s.lights.size()) << name;
        EXPECT_FALSE(s.features.glossy || s.features.thin_lens || s.features.area_lights) << name;
        for (const auto& m : s.materials) EXPECT_EQ(m.area_light, -1) << name;
    }
}

TEST_F(NffExtensions, BadValuesNameTheLine) {
    const std::string v = kView;
    expect_error(v + "la 0 0 0  1 0 0  2 0 0\n", 8, "zero or parallel");
    expect_error(v + "la 0 0 0  0 0 0  0 1 0\n", 8, "zero or parallel");
    expect_error(v + "la 0 0 0  1 0 0  0 1 0  1 -1 1\n", 8, "negative light colour");
    expect_error(v + "la 0 0 0  1 0 0\n", 8, "unexpected end of file");
    expect_error(v + "ls 0 0 0 0\n", 8, "radius must be positive");
    expect_error(v + "ls 0 0 0 -1\n", 8, "radius must be positive");
    expect_error(v + "ld 0 0 0\n", 8, "zero light direction");
    expect_error(v + "ld 0 nan 1\n", 8, "non-finite");
    expect_error(v + "lens -1 2\n", 8, "negative lens radius");
    expect_error(v + "lens 1 0\n", 8, "focus distance must be positive");
    expect_error(v + "lens 1 2\nlens 1 3\n", 9, "second 'lens' line");
    expect_error(v + "gloss -3\n", 8, "negative gloss");
    expect_error(v + "gloss\n", 8, "unexpected end of file");
    expect_error(v + "obj\n", 8, "unexpected end of file");
    expect_error(v + "\nobj missing.obj\n", 9, "cannot open file");
    write("broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
    expect_error(v + "obj broken.obj\n", 8, "broken.obj:3: vertex index out of range");
}

TEST(Cornell, GeneratedBoxMatchesThePublishedGeometry) {
    const Scene s = raypack::load_scene("gen:cornell:1");
    // 5 walls + 10 block faces as quads, plus the light: 32 triangles.
    EXPECT_EQ(s.triangles.size(), 32u);
    EXPECT_EQ(s.spheres.size(), 0u);
    ASSERT_EQ(s.area_lights.size(), 1u);
    const auto& l = s.area_lights[0];
    EXPECT_FLOAT_EQ(l.area(), 130.0f * 105.0f);  // 213..343 by 227..332 mm
    EXPECT_LT(triangle_normal(s, l.first_prim).y, 0);  // it shines down
    const raypack::Box3f b = raypack::scene_bounds(s);
    EXPECT_EQ(b.lo, (Vec3f{0, 0, 0}));
    EXPECT_EQ(b.hi, (Vec3f{556, 548.8f, 559.2f}));
    EXPECT_EQ(s.camera.from, (Vec3f{278, 273, -800}));
    // 35 mm focal length, 25 mm film: fov 2 atan(12.5 / 35).
    EXPECT_NEAR(s.camera.fov_deg, 2 * std::atan(12.5 / 35) * 180 / M_PI, 1e-3);

    const Scene spheres = raypack::load_scene("gen:cornell:2");
    EXPECT_EQ(spheres.triangles.size(), 12u);
    ASSERT_EQ(spheres.spheres.size(), 2u);
    EXPECT_TRUE(spheres.features.reflection && spheres.features.transmission);
    for (std::size_t i = 0; i < 2; ++i)  // resting on the floor
        EXPECT_EQ(spheres.spheres.center[i].y, spheres.spheres.radius[i]);
}

TEST(SceneVariants, GeneratedScenesWithAreaLightsLensAndGloss) {
    const Scene plain = raypack::load_scene("gen:balls:2");
    const Scene all = raypack::load_scene("gen:balls:2:area-lights+lens+glossy");
    // Every point light becomes a sphere light where it was.
    EXPECT_TRUE(all.lights.empty());
    ASSERT_EQ(all.area_lights.size(), plain.lights.size());
    const float distance = length(plain.camera.from - plain.camera.at);
    for (std::size_t i = 0; i < plain.lights.size(); ++i) {
        EXPECT_EQ(all.area_lights[i].center, plain.lights[i].position);
        EXPECT_NEAR(all.area_lights[i].radius, 0.05f * distance, 1e-4f * distance);
    }
    EXPECT_EQ(all.light_count(), plain.light_count());  // the SPD intensity stays the same
    EXPECT_NEAR(all.camera.focus_distance, distance, 1e-4f * distance);
    EXPECT_NEAR(all.camera.lens_radius, 0.02f * distance, 1e-4f * distance);
    EXPECT_TRUE(all.features.glossy && all.features.thin_lens && all.features.area_lights);
    for (std::uint32_t p = 0; p < all.primitive_count(); ++p) {
        const auto& m = all.materials[all.prim_material[p]];
        if (m.area_light < 0) {
            EXPECT_EQ(m.gloss, 40.0f);  // every surface but the lights' own
        }
    }
    // The geometry is the plain scene's plus the lights' spheres.
    EXPECT_EQ(all.primitive_count(), plain.primitive_count() + plain.lights.size());
    const Scene lens_only = raypack::load_scene("gen:tetra:2:lens");
    EXPECT_TRUE(lens_only.features.thin_lens);
    EXPECT_FALSE(lens_only.features.area_lights || lens_only.features.glossy);
    EXPECT_THROW(raypack::load_scene("gen:balls:2:fog"), raypack::SceneError);
    EXPECT_THROW(raypack::load_scene("gen:balls:2:"), raypack::SceneError);
}
