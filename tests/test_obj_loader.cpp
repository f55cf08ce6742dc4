// The OBJ loader: the Stanford bunny from scenes/, small hand-written meshes,
// the camera it makes up, and its errors.
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <unistd.h>

#include "scene/load.h"
#include "tests/scene_files.h"

namespace {

using raypack::Scene;
using raypack::SceneError;
using raypack::Vec3d;
using raypack::Vec3f;

}  // namespace

class ObjLoader : public SceneFiles {
protected:
    ObjLoader() : SceneFiles(raypack::load_obj_file, ".obj") {}
};

TEST_F(ObjLoader, BunnyLoadsWithAFramingCamera) {
    const std::string path = std::string(RAYPACK_SOURCE_DIR) + "/scenes/bunny.obj";
    const Scene s = raypack::load_scene(path);
    EXPECT_EQ(s.source, path);
    EXPECT_EQ(s.triangles.size(), 69451u);
    EXPECT_EQ(s.primitive_count(), 69451u);
    EXPECT_EQ(s.spheres.size(), 0u);
    EXPECT_EQ(s.cones.size(), 0u);
    EXPECT_TRUE(s.features.triangles);
    EXPECT_FALSE(s.features.vertex_normals);
    EXPECT_FALSE(s.features.spheres);
    EXPECT_FALSE(s.features.reflection);
    EXPECT_FALSE(s.features.transmission);

    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].kd, 0.8f);
    EXPECT_EQ(s.materials[0].color, (Vec3f{0.8f, 0.8f, 0.8f}));
    EXPECT_EQ(s.materials[0].ks, 0.0f);

    // Bounds of the referenced vertices (scenes/SOURCES.md gives all vertices').
    const raypack::Box3f b = raypack::scene_bounds(s);
    EXPECT_NEAR(b.lo.x, -0.09469f, 1e-4);
    EXPECT_NEAR(b.lo.y, 0.03299f, 1e-4);
    EXPECT_NEAR(b.lo.z, -0.06187f, 1e-4);
    EXPECT_NEAR(b.hi.x, 0.06101f, 1e-4);
    EXPECT_NEAR(b.hi.y, 0.1873f, 1e-4);
    EXPECT_NEAR(b.hi.z, 0.0588f, 1e-4);

    ASSERT_TRUE(s.has_camera);
    const raypack::Camera& c = s.camera;
    EXPECT_EQ(c.up, (Vec3f{0, 1, 0}));
    EXPECT_EQ(c.fov_deg, 45.0f);
    EXPECT_EQ(c.width, 512);
    EXPECT_EQ(c.height, 512);
    const Vec3f centre = b.center();
    EXPECT_NEAR(c.at.x, centre.x, 1e-6);
    EXPECT_NEAR(c.at.y, centre.y, 1e-6);
    EXPECT_NEAR(c.at.z, centre.z, 1e-6);
    const Vec3d view = raypack::normalize(Vec3d(c.from - c.at));
    const Vec3d dir = raypack::normalize(Vec3d{1, 0.6, 1.4});
    EXPECT_NEAR(raypack::dot(view, dir), 1.0, 1e-6);

    // Every vertex within the field of view, and the view not much wider
    // than needed; nothing closer than hither.
    const double half_fov = 22.5 * std::numbers::pi / 180;
    double widest = 0, nearest = INFINITY;
    for (const auto* ps : {&s.triangles.p0, &s.triangles.p1, &s.triangles.p2})
        for (const Vec3f& p : *ps) {
            const Vec3d to = Vec3d(p - c.from);
            widest = std::max(widest, std::acos(std::min(1.0, raypack::dot(raypack::normalize(to), -view))));
            nearest = std::min(nearest, raypack::length(to));
        }
    EXPECT_LE(widest, half_fov + 1e-6);
    EXPECT_GT(widest, 0.5 * half_fov);
    EXPECT_GT(c.hither, 0.0f);
    EXPECT_LT(c.hither, 0.1 * nearest);

    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_FALSE(s.lights[0].has_color);
    EXPECT_GT(s.lights[0].position.y, c.from.y);
}

TEST_F(ObjLoader, FacesNormalsAndIndices) {
    const Scene s = load(
        "# a quad with normals, then a triangle without, by relative indices\n"
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "vn 0 0 1\nvn 0 0.6 0.8\n"
        "vt 0 0\n"
        "f 1//1 2//1 3//2 4//2\n"
        "f -4/1 -3/1 -1/1\n");
    ASSERT_EQ(s.triangles.size(), 3u);
    EXPECT_EQ(s.triangles.p0[0], (Vec3f{0, 0, 0}));
    EXPECT_EQ(s.triangles.p2[0], (Vec3f{1, 1, 0}));
    EXPECT_EQ(s.triangles.p2[1], (Vec3f{0, 1, 0}));
    EXPECT_EQ(s.triangles.has_normals[0], 1);
    EXPECT_EQ(s.triangles.n0[0], (Vec3f{0, 0, 1}));
    EXPECT_EQ(s.triangles.n2[0], (Vec3f{0, 0.6f, 0.8f}));
    EXPECT_EQ(s.triangles.n2[1], (Vec3f{0, 0.6f, 0.8f}));
    EXPECT_EQ(s.triangles.has_normals[2], 0);
    EXPECT_EQ(s.triangles.p1[2], (Vec3f{1, 0, 0}));
    EXPECT_TRUE(s.features.vertex_normals);
}

TEST_F(ObjLoader, ConcaveFaceAndGroupsAndMaterials) {
    // Material statements are ignored (one grey material), even when the
    // .mtl file is missing.
    const Scene s = load(
        "mtllib missing.mtl\no thing\ng part\nusemtl red\ns 1\n"
        "v 0 2 0\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\n"
        "f 1 2 3 4 5 6\n"
        "g other\nusemtl blue\nf 1 2 3\n");
    ASSERT_EQ(s.triangles.size(), 5u);
    double area = 0;
    for (std::size_t i = 0; i < 4; ++i) {
        const Vec3f n = raypack::cross(s.triangles.p1[i] - s.triangles.p0[i], s.triangles.p2[i] - s.triangles.p0[i]);
        EXPECT_GE(n.z, 0.0f);
        area += 0.5 * n.z;
    }
    EXPECT_DOUBLE_EQ(area, 3.0);
    EXPECT_EQ(s.materials.size(), 1u);
    EXPECT_TRUE(s.has_camera);
}

TEST_F(ObjLoader, RelativeIndicesCountFromTheirLineAndColoursAreSkipped) {
    // -1 is the last vertex defined before the face's line, whatever comes
    // after; positive indices may name vertices defined later; "v x y z w"
    // and "v x y z r g b" keep x y z; a statement raypack does not use
    // ("l", "p", "vp", "curv") is skipped.
    const Scene s = load(
        "v 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\n"
        "f -3 -2 -1\n"
        "v 5 5 5\n"
        "f -4 -3 -2\n"
        "f 1 2 5\n"
        "l 1 2\np 1\nvp 0.5\n"
        "v 0 0 7\n");
    ASSERT_EQ(s.triangles.size(), 3u);
    EXPECT_EQ(s.triangles.p0[0], (Vec3f{0, 0, 0}));
    EXPECT_EQ(s.triangles.p1[0], (Vec3f{1, 0, 0}));
    EXPECT_EQ(s.triangles.p2[0], (Vec3f{0, 1, 0}));
    EXPECT_EQ(s.triangles.p2[1], (Vec3f{0, 1, 0}));  // -2 on the line after "v 5 5 5"
    EXPECT_EQ(s.triangles.p2[2], (Vec3f{0, 0, 7}));  // defined after the face
}

TEST_F(ObjLoader, ZeroNormalsFallBackToFlat) {
    const Scene s = load("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nvn 0 0 1\nf 1//1 2//2 3//2\n");
    ASSERT_EQ(s.triangles.size(), 1u);
    EXPECT_EQ(s.triangles.has_normals[0], 0);
}

TEST_F(ObjLoader, UppercaseExtension) {
    EXPECT_EQ(raypack::load_scene(write("MESH.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")).triangles.size(), 1u);
}

TEST_F(ObjLoader, Errors) {
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";  // lines 1-3
    expect_error(tri + "v 0 nan 0\nf 1 2 3\n", 4, "non-finite number 'nan'");
    expect_error(tri + "v 0 1e999 0\nf 1 2 3\n", 4, "non-finite number '1e999'");
    expect_error(tri + "vn 0 0 inf\nf 1 2 3\n", 4, "non-finite number");
    expect_error(tri + "v 0 x 0\nf 1 2 3\n", 4, "expected a number");
    expect_error(tri + "v 0 1\nf 1 2 3\n", 4, "needs 3 coordinates");
    expect_error(tri + "f 1 2 9\n", 4, "vertex index out of range");
    expect_error(tri + "f -1 -2 -4\n", 4, "vertex index out of range");
    expect_error(tri + "vn 0 0 1\nf 1//1 2//1 3//2\n", 5, "normal index out of range");
    expect_error(tri + "f 1 2\n", 4, "at least 3 vertices");
    expect_error(tri + "\n\nf 0 1 2\n", 6, "index 0 in face");
    expect_error(tri + "f 1 2 x\n", 4, "bad vertex reference 'x'");
    expect_error(tri + "f 1 2 3/1/1/1\n", 4, "bad vertex reference");
    expect_error(tri + "f 1 2 3//\n", 4, "bad vertex reference");
    expect_error(tri + "f 1 2 99999999999999999999\n", 4, "bad vertex reference");
    expect_error(tri, 0, "no faces");
    expect_error("", 0, "no faces");
    std::string big = "f";
    for (int i = 0; i < 300; ++i) big += " 1";
    expect_error(tri + big + "\n", 4, "at most 255");
    try {
        raypack::load_obj_file((dir_ / "missing.obj").string());
        ADD_FAILURE();
    } catch (const SceneError& e) {
        EXPECT_EQ(e.file(), (dir_ / "missing.obj").string());
        EXPECT_NE(e.problem().find("cannot open"), std::string::npos);
    }
}
