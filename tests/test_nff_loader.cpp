// The NFF loader against the shipped SPD scenes (counts from scenes/SOURCES.md)
// and against small hand-written files, good and bad.
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "scene/load.h"
#include "tests/scene_files.h"

namespace {

using raypack::PrimKind;
using raypack::Scene;
using raypack::SceneError;
using raypack::Vec3f;

std::string scene_path(const std::string& file) { return std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file; }

}  // namespace

class NffLoader : public SceneFiles {
protected:
    NffLoader() : SceneFiles(raypack::load_nff_file, ".nff") {}
};

namespace {

constexpr const char* kView =
    "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.1\nresolution 64 32\n";  // lines 1-7

struct Expected {
    const char* file;
    std::size_t spheres, triangles, cones, lights;
    bool reflection, transmission, vertex_normals;
    Vec3f from, at, up;
    float hither;
};

// Counts from scenes/SOURCES.md; polygons of n vertices count n-2 triangles:
// gears 9,217 quads + 128 144-gons = 2 * 9,217 + 142 * 128 = 36,610.
const Expected kScenes[] = {
    {"balls.nff", 7381, 2, 0, 3, true, false, false, {2.1f, 1.3f, 1.7f}, {0, 0, 0}, {0, 0, 1}, 0.01f},
    {"gears.nff", 0, 36610, 0, 5, true, true, false, {-1.1f, -2.1f, 2.6f}, {0, 0, 0}, {0, 0, 1}, 1},
    {"mount.nff", 4, 8192, 0, 1, true, true, false, {-1.6f, 1.6f, 1.7f}, {0, 0, 0}, {0, 0, 1}, 0.01f},
    {"rings.nff", 4200, 2, 4200, 3, true, false, false, {-1, -2.61313f, 0.5f}, {-1, -1.61313f, 0.5f}, {0, 0, 1}, 1},
    {"teapot.nff", 0, 2256 + 72, 0, 2, true, false, true, {4.86f, 7.2f, 5.4f}, {0, 0, 0}, {0, 0, 1}, 1},
    {"tetra.nff", 0, 4096, 0, 1, false, false, false, {1.02285f, -3.17715f, -2.17451f},
     {-0.004103f, -0.004103f, 0.216539f}, {-0.816497f, -0.816497f, 0.816497f}, 1},
    {"tree.nff", 4095, 2, 4095, 7, false, false, false, {4.5f, 0.4f, 2}, {0, 0, 1.5f}, {0, 0, 1}, 1},
};

}  // namespace

TEST_F(NffLoader, ShippedScenesLoadWithExactCountsCamerasAndFeatures) {
    for (const Expected& x : kScenes) {
        SCOPED_TRACE(x.file);
        const Scene s = raypack::load_scene(scene_path(x.file));
        EXPECT_EQ(s.source, scene_path(x.file));
        EXPECT_EQ(s.spheres.size(), x.spheres);
        EXPECT_EQ(s.triangles.size(), x.triangles);
        EXPECT_EQ(s.cones.size(), x.cones);
        EXPECT_EQ(s.primitive_count(), x.spheres + x.triangles + x.cones);
        EXPECT_EQ(s.prim_material.size(), s.primitive_count());
        EXPECT_EQ(s.lights.size(), x.lights);
        for (const auto& l : s.lights) EXPECT_FALSE(l.has_color);
        EXPECT_EQ(s.background, (Vec3f{0.078f, 0.361f, 0.753f}));

        ASSERT_TRUE(s.has_camera);
        EXPECT_EQ(s.camera.from, x.from);
        EXPECT_EQ(s.camera.at, x.at);
        EXPECT_EQ(s.camera.up, x.up);
        EXPECT_EQ(s.camera.fov_deg, 45.0f);
        EXPECT_EQ(s.camera.hither, x.hither);
        EXPECT_EQ(s.camera.width, 512);
        EXPECT_EQ(s.camera.height, 512);

        const auto& f = s.features;
        EXPECT_EQ(f.spheres, x.spheres > 0);
        EXPECT_EQ(f.triangles, x.triangles > 0);
        EXPECT_EQ(f.cones, x.cones > 0);
        EXPECT_EQ(f.reflection, x.reflection);
        EXPECT_EQ(f.transmission, x.transmission);
        EXPECT_EQ(f.vertex_normals, x.vertex_normals);
        EXPECT_FALSE(f.colored_lights);
        EXPECT_FALSE(f.inside_only);
    }
}

TEST_F(NffLoader, BallsFirstAndLastPrimitives) {
    const Scene s = raypack::load_nff_file(scene_path("balls.nff"));
    // The ground quad comes first in the file, then the sphereflake.
    ASSERT_EQ(s.prims[0].kind, PrimKind::Triangle);
    ASSERT_EQ(s.prims[1].kind, PrimKind::Triangle);
    EXPECT_EQ(s.triangles.p0[0], (Vec3f{12, 12, -0.5f}));
    EXPECT_EQ(s.prims[2].kind, PrimKind::Sphere);
    EXPECT_EQ(s.materials[s.prim_material[0]].color, (Vec3f{1, 0.75f, 0.33f}));
    EXPECT_EQ(s.materials[s.prim_material[2]].ks, 0.5f);
}

TEST_F(NffLoader, TeapotPatchNormalsGoIntoTheNormalSlots) {
    const Scene s = raypack::load_nff_file(scene_path("teapot.nff"));
    // The first pp in the file (line 194).
    std::size_t i = 0;
    while (!s.triangles.has_normals[i]) ++i;
    EXPECT_EQ(s.triangles.p0[i], (Vec3f{1.4f, 0, 2.4f}));
    EXPECT_EQ(s.triangles.n0[i], (Vec3f{-0.902861f, -0.0f, -0.429934f}));
    EXPECT_EQ(s.triangles.p2[i], (Vec3f{1.33276f, -0.370922f, 2.45469f}));
    EXPECT_EQ(s.triangles.n2[i], (Vec3f{-0.953562f, 0.257047f, -0.156989f}));
    std::size_t with_normals = 0;
    for (auto h : s.triangles.has_normals) with_normals += h;
    EXPECT_EQ(with_normals, 2256u);
}

TEST_F(NffLoader, GlobalNumberingFollowsTheFile) {
    const Scene s = load(std::string(kView) +
                         "s 0 0 0 1\n"
                         "p 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                         "c 0 0 0 1 0 0 1 0.5\n"
                         "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n"
                         "s 1 1 1 -2\n");
    ASSERT_EQ(s.primitive_count(), 6u);
    const PrimKind kinds[] = {PrimKind::Sphere, PrimKind::Triangle, PrimKind::Triangle,
                              PrimKind::Cone,   PrimKind::Triangle, PrimKind::Sphere};
    const std::uint32_t index[] = {0, 0, 1, 0, 2, 1};
    for (std::size_t i = 0; i < 6; ++i) {
        EXPECT_EQ(s.prims[i].kind, kinds[i]) << i;
        EXPECT_EQ(s.prims[i].index, index[i]) << i;
    }
    // The quad is the fan (0,1,2), (0,2,3).
    EXPECT_EQ(s.triangles.p1[1], (Vec3f{1, 1, 0}));
    EXPECT_EQ(s.triangles.p2[1], (Vec3f{0, 1, 0}));
    EXPECT_EQ(s.triangles.has_normals[2], 1);
    EXPECT_EQ(s.spheres.radius[1], 2.0f);
    EXPECT_EQ(s.spheres.inside_only[1], 1);
    EXPECT_TRUE(s.features.inside_only);
    EXPECT_TRUE(s.features.vertex_normals);
    // Objects before any "f" get one default material.
    ASSERT_EQ(s.materials.size(), 1u);
    for (auto m : s.prim_material) EXPECT_EQ(m, 0u);
}

TEST_F(NffLoader, ConsecutiveObjectsShareTheirMaterial) {
    const Scene s = load(std::string(kView) +
                         "f 1 0 0 0.7 0.3 10 0 1\ns 0 0 0 1\ns 2 0 0 1\n"
                         "f 0 1 0 0.5 0 0 0.5 1.5\ns 4 0 0 1\n");
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.prim_material[0], 0u);
    EXPECT_EQ(s.prim_material[1], 0u);
    EXPECT_EQ(s.prim_material[2], 1u);
    const raypack::Material& m = s.materials[1];
    EXPECT_EQ(m.color, (Vec3f{0, 1, 0}));
    EXPECT_EQ(m.kd, 0.5f);
    EXPECT_EQ(m.ks, 0.0f);
    EXPECT_EQ(m.shine, 0.0f);
    EXPECT_EQ(m.transmittance, 0.5f);
    EXPECT_EQ(m.ior, 1.5f);
    EXPECT_TRUE(s.features.reflection);
    EXPECT_TRUE(s.features.transmission);
}

TEST_F(NffLoader, ThreeLineConeEqualsOneLineCone) {
    const Scene a = load(std::string(kView) + "c 1 2 3 0.5 4 5 6 0.25\n");
    const Scene b = load(std::string(kView) + "c\n1 2 3 0.5\n4 5 6 0.25\n");
    ASSERT_EQ(a.cones.size(), 1u);
    ASSERT_EQ(b.cones.size(), 1u);
    EXPECT_EQ(a.cones.base[0], b.cones.base[0]);
    EXPECT_EQ(a.cones.apex[0], b.cones.apex[0]);
    EXPECT_EQ(a.cones.base[0], (Vec3f{1, 2, 3}));
    EXPECT_EQ(a.cones.apex[0], (Vec3f{4, 5, 6}));
    EXPECT_EQ(a.cones.base_radius[0], 0.5f);
    EXPECT_EQ(b.cones.apex_radius[0], 0.25f);
    EXPECT_EQ(a.cones.inside_only[0], 0);
    // Both radii negative: inside only.
    const Scene c = load(std::string(kView) + "c\n1 2 3 -0.5\n4 5 6 -0.25\n");
    EXPECT_EQ(c.cones.inside_only[0], 1);
    EXPECT_EQ(c.cones.base_radius[0], 0.5f);
}

TEST_F(NffLoader, CommentsAreIgnored) {
    const Scene s = load("# a scene\n" + std::string(kView) +
                         "s 0 0 0 1 # a sphere\n"
                         "#s 9 9 9 9\n"
                         "   # indented comment with keywords p 3 s c\n"
                         "s 1 1 1 2#glued\n");
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_EQ(s.spheres.radius[1], 2.0f);
    // Comments still count lines: the error below is on line 3.
    expect_error("# one\n# two\nbogus\n", 3, "unknown keyword 'bogus'");
}

TEST_F(NffLoader, LightsWithAndWithoutColour) {
    const Scene s = load(std::string(kView) +
                         "l 1 2 3\n"
                         "l 4 5 6 0.5 0.25 1\n"
                         "l 7 8 9\n"
                         "s 0 0 0 1\n");
    ASSERT_EQ(s.lights.size(), 3u);
    EXPECT_EQ(s.lights[0].position, (Vec3f{1, 2, 3}));
    EXPECT_FALSE(s.lights[0].has_color);
    EXPECT_EQ(s.lights[0].color, (Vec3f{1, 1, 1}));
    EXPECT_TRUE(s.lights[1].has_color);
    EXPECT_EQ(s.lights[1].color, (Vec3f{0.5f, 0.25f, 1}));
    EXPECT_FALSE(s.lights[2].has_color);
    EXPECT_EQ(s.lights[2].position, (Vec3f{7, 8, 9}));
    EXPECT_TRUE(s.features.colored_lights);
    // A light as the last entity, with and without colour.
    EXPECT_EQ(load("l 1 2 3").lights.size(), 1u);
    EXPECT_TRUE(load("l 1 2 3 1 1 1").lights[0].has_color);
    expect_error("l 1 2 3 0.5 s 0 0 0 1\n", 1, "expected a number");
}

TEST_F(NffLoader, CameraIsReadAndOptional) {
    const Scene s = load("b 0.1 0.2 0.3\n" + std::string(kView));
    ASSERT_TRUE(s.has_camera);
    EXPECT_EQ(s.camera.from, (Vec3f{0, 0, 5}));
    EXPECT_EQ(s.camera.up, (Vec3f{0, 1, 0}));
    EXPECT_EQ(s.camera.hither, 0.1f);
    EXPECT_EQ(s.camera.width, 64);
    EXPECT_EQ(s.camera.height, 32);
    EXPECT_EQ(s.background, (Vec3f{0.1f, 0.2f, 0.3f}));
    // Objects before the view are accepted; so is no view at all.
    EXPECT_TRUE(load("s 0 0 0 1\n" + std::string(kView)).has_camera);
    const Scene none = load("s 0 0 0 1\n");
    EXPECT_FALSE(none.has_camera);
    EXPECT_EQ(none.spheres.size(), 1u);
}

TEST_F(NffLoader, ConcavePolygonIsTriangulatedByArea) {
    // An L: a fan from vertex 0 would put a triangle outside it.
    const Scene s = load("p 6\n0 2 0\n0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n");
    ASSERT_EQ(s.triangles.size(), 4u);
    double area = 0;
    for (std::size_t i = 0; i < 4; ++i) {
        const Vec3f n = raypack::cross(s.triangles.p1[i] - s.triangles.p0[i], s.triangles.p2[i] - s.triangles.p0[i]);
        EXPECT_GE(n.z, 0.0f);
        area += 0.5 * n.z;
    }
    EXPECT_DOUBLE_EQ(area, 3.0);
    // Degenerate (collinear) polygons load as zero-area fans.
    EXPECT_EQ(load("p 4\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n").triangles.size(), 2u);
}

TEST_F(NffLoader, ToleratesCrlfTabsAndPlusSigns) {
    const Scene s = load("s\t+1 0 0 1\r\ns 0 0 0 1e-50\r\n");
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_EQ(s.spheres.center[0], (Vec3f{1, 0, 0}));
    EXPECT_EQ(s.spheres.radius[1], 0.0f);  // underflow is zero, not an error
}

TEST_F(NffLoader, StreamAndLoadScene) {
    std::istringstream in("s 0 0 0 1\np 3\n0 0 0 1 0 0 0 1 0\n");
    const Scene s = raypack::load_nff(in, "memory");
    EXPECT_EQ(s.source, "memory");
    EXPECT_EQ(s.primitive_count(), 2u);
    std::istringstream bad("s 0 0 0\n");
    try {
        raypack::load_nff(bad, "memory");
        ADD_FAILURE();
    } catch (const SceneError& e) {
        EXPECT_STREQ(e.what(), "memory:1: unexpected end of file: expected sphere radius ('s' on line 1)");
    }
    // Extension is case-insensitive.
    const std::string upper = write("UPPER.NFF", "s 0 0 0 1\n");
    EXPECT_EQ(raypack::load_scene(upper).spheres.size(), 1u);
}

TEST_F(NffLoader, GeneratedScenes) {
    const Scene s = raypack::load_scene("gen:tetra:6");
    EXPECT_EQ(s.source, "gen:tetra:6");
    EXPECT_EQ(s.triangles.size(), 4096u);
    EXPECT_TRUE(s.has_camera);
    const Scene ref = raypack::load_nff_file(scene_path("tetra.nff"));
    EXPECT_EQ(s.triangles.p0, ref.triangles.p0);
    EXPECT_EQ(s.triangles.p2, ref.triangles.p2);
}

TEST_F(NffLoader, BadGeneratorSpecs) {
    for (const char* spec : {"gen:balls", "gen:balls:", "gen:balls:x", "gen:balls:4x", "gen:balls:1.5",
                             "gen::4", "gen:nosuchscene:4", "gen:balls:99999999999", "gen:balls:0"}) {
        SCOPED_TRACE(spec);
        try {
            raypack::load_scene(spec);
            ADD_FAILURE() << "no error";
        } catch (const SceneError& e) {
            EXPECT_EQ(e.file(), spec);
            EXPECT_EQ(e.line(), 0);
            EXPECT_EQ(std::string(e.what()).rfind(std::string(spec) + ":0: bad generator spec", 0), 0u) << e.what();
        }
    }
}

TEST_F(NffLoader, MissingFileAndUnknownFormat) {
    const std::string missing = (dir_ / "nope.nff").string();
    for (const std::string& spec : {missing, (dir_ / "nope.obj").string()}) {
        try {
            raypack::load_scene(spec);
            ADD_FAILURE();
        } catch (const SceneError& e) {
            EXPECT_EQ(e.file(), spec);
            EXPECT_EQ(e.line(), 0);
            EXPECT_NE(e.problem().find("cannot open"), std::string::npos) << e.what();
        }
    }
    for (const std::string& spec : {write("scene.txt", "s 0 0 0 1\n"), (dir_ / "noext").string()}) {
        try {
            raypack::load_scene(spec);
            ADD_FAILURE();
        } catch (const SceneError& e) {
            EXPECT_EQ(e.file(), spec);
            EXPECT_NE(e.problem().find("expected a .nff or .obj"), std::string::npos) << e.what();
        }
    }
    std::filesystem::create_directories(dir_ / "dir.nff");
    EXPECT_THROW(raypack::load_scene((dir_ / "dir.nff").string()), SceneError);
}

TEST_F(NffLoader, ErrorsNameFileLineAndProblem) {
    const std::string v = kView;  // 7 lines
    expect_error(v + "s 0 0 0 1\nq 1 2 3\n", 9, "unknown keyword 'q'");
    expect_error(v + "s 0 0 0 1 2\n", 8, "unexpected number '2'");
    // Truncated polygon at the end of the file: reported where the file stops.
    expect_error(v + "p 4\n0 0 0\n1 0 0\n1 1 0\n", 11, "unexpected end of file");
    expect_error(v + "p 4\n0 0 0\n1 0 0\n1 1 0\n", 11, "vertex 4 of 4");
    expect_error(v + "p 4\n0 0 0\n1 0 0\n1 1 0\ns 0 0 0 1\n", 12, "expected a number");
    expect_error(v + "p 4\n0 0 0\n1 0 0\n1 1 0\ns 0 0 0 1\n", 12, "'p' on line 8");
    expect_error(v + "p\n", 8, "unexpected end of file");
    // Non-finite numbers, as text or after parsing.
    expect_error(v + "s 0 0 nan 1\n", 8, "non-finite number 'nan'");
    expect_error(v + "s 0 0 1e999 1\n", 8, "non-finite number '1e999'");
    expect_error(v + "s 0 0 0 -inf\n", 8, "non-finite number");
    expect_error(v + "s 0 0 1e39 1\n", 8, "non-finite number");  // finite double, not float
    expect_error("l 1 2 3 nan 1 1\n", 1, "non-finite number");
    expect_error(v + "s 0 0 x 1\n", 8, "expected a number for sphere centre");
    expect_error(v + "s 0 0 1.5.5 1\n", 8, "expected a number");
    // Counts.
    expect_error(v + "p 1000000000\n", 8, "exceeds the limit");
    expect_error(v + "p 99999999999999999999999\n", 8, "out of range");
    expect_error(v + "p -3\n0 0 0\n", 8, "negative vertex count");
    expect_error(v + "p 2\n0 0 0\n1 1 1\n", 8, "at least 3 vertices");
    expect_error(v + "pp 3.0\n", 8, "expected an integer");
    expect_error(v + "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 0\n0 1 0 0 0 1\n", 10, "zero-length vertex normal");
    // Cones.
    expect_error(v + "c\n1 1 1 1\n1 1 1 0.5\n", 10, "cone base and apex coincide");
    expect_error(v + "c 0 0 0 1 0 0 1 -1\n", 8, "opposite signs");
    // Material.
    expect_error(v + "f 1 1 1 1 0 0 0\ns 0 0 0 1\n", 9, "index of refraction");
}

TEST_F(NffLoader, ViewpointErrors) {
    const std::string tail = "hither 1\nresolution 512 512\n";
    auto view = [](const std::string& from, const std::string& at, const std::string& up, const std::string& angle) {
        return "v\nfrom " + from + "\nat " + at + "\nup " + up + "\nangle " + angle + "\n";
    };
    expect_error(view("0 0 5", "0 0 0", "0 1 0", "0") + tail, 5, "not in (0, 180)");
    expect_error(view("0 0 5", "0 0 0", "0 1 0", "180") + tail, 5, "not in (0, 180)");
    expect_error(view("0 0 5", "0 0 0", "0 1 0", "-10") + tail, 5, "not in (0, 180)");
    expect_error(view("0 0 5", "0 0 0", "0 0 0", "45") + tail, 4, "zero-length up");
    expect_error(view("1 2 3", "1 2 3", "0 1 0", "45") + tail, 3, "from and at coincide");
    expect_error(view("0 0 5", "0 0 0", "0 0 2", "45") + tail, 4, "parallel to the view direction");
    expect_error(view("0 0 5", "0 0 0", "0 1 0", "45") + "hither -1\nresolution 5 5\n", 6, "negative hither");
    expect_error(view("0 0 5", "0 0 0", "0 1 0", "45") + "hither 1\nresolution 0 512\n", 7, "resolution");
    expect_error(view("0 0 5", "0 0 0", "0 1 0", "45") + "hither 1\nresolution 512 65537\n", 7, "not in 1..65536");
    expect_error(view("0 0 5", "0 0 0", "0 1 0", "45") + "hither 1\nresolution 512 51.2\n", 7, "expected an integer");
    expect_error("v\nat 0 0 0\nfrom 0 0 5\n", 2, "expected 'from'");
    expect_error(view("0 0 5", "0 0 0", "0 1 0", "45") + "resolution 512 512\n", 6, "expected 'hither'");
    expect_error("v\nfrom 0 0 5\nat 0 0 0\n", 3, "unexpected end of file: expected 'up'");
    expect_error(std::string(kView) + "s 0 0 0 1\n" + kView, 9, "second viewpoint");
}
