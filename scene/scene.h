#pragma once
// The scene as structure of arrays: one set of arrays per primitive kind,
// plus a global numbering of primitives in the order the file defines them.
#include <cstdint>
#include <string>
#include <vector>

#include "kernels/aabb.h"
#include "kernels/height_field.h"

namespace raypack {

enum class PrimKind : std::uint8_t { Sphere, Triangle, Cone, HeightField };

/// Scene-global primitive number -> kind and index into that kind's arrays.
struct PrimRef {
    PrimKind kind;
    std::uint32_t index;
};

/// NFF fill: "f red green blue Kd Ks Shine T index_of_refraction".
struct Material {
    Vec3f color{1, 1, 1};
    float kd = 1;
    float ks = 0;
    float shine = 0;
    float transmittance = 0;
    float ior = 1;
    /// NFF extension `gloss n`: reflection samples a Phong lobe cos^n around
    /// the mirror direction; 0 is the perfect mirror of plain NFF.
    float gloss = 0;
    /// The area light (index into Scene::area_lights) whose surface this
    /// material covers, or -1: camera and secondary rays that hit it see it.
    std::int32_t area_light = -1;
};

struct PointLight {
    Vec3f position;
    Vec3f color{1, 1, 1};
    bool has_color = false;  ///< NFF lights may omit their colour.
};

enum class AreaLightShape : std::uint8_t { Parallelogram, Sphere };

/// NFF extensions `la` (a parallelogram corner + s edge1 + t edge2, s, t in
/// [0, 1], emitting from the side cross(edge1, edge2) points to) and `ls` (a
/// sphere emitting outwards). Its surface is also geometry of the scene
/// (primitives [first_prim, first_prim + prim_count)), so rays see it.
struct AreaLight {
    AreaLightShape shape = AreaLightShape::Parallelogram;
    Vec3f corner, edge1, edge2;  ///< Parallelogram
    Vec3f center;                ///< Sphere
    float radius = 0;            ///< Sphere
    Vec3f color{1, 1, 1};
    bool has_color = false;
    std::uint32_t first_prim = 0, prim_count = 0;

    float area() const;
};

/// NFF extension `ld`: light arriving from infinitely far along `direction`
/// (unit length, the way the light travels).
struct DistantLight {
    Vec3f direction{0, 0, -1};
    Vec3f color{1, 1, 1};
    bool has_color = false;
};

/// NFF viewpoint. fov_deg spans the centres of the top and bottom pixel rows.
struct Camera {
    Vec3f from{0, 0, 1};
    Vec3f at{0, 0, 0};
    Vec3f up{0, 1, 0};
    float fov_deg = 45;
    float hither = 0;
    int width = 512;
    int height = 512;
    /// NFF extension `lens radius focus`: a thin lens of this aperture
    /// radius focused at this distance along the view direction; radius 0
    /// is the pinhole of plain NFF.
    float lens_radius = 0;
    float focus_distance = 0;
};

struct SphereSoA {
    std::vector<Vec3f> center;
    std::vector<float> radius;      ///< always >= 0
    std::vector<std::uint8_t> inside_only;  ///< NFF negative radius: only the inside is visible
    std::size_t size() const { return radius.size(); }
};

/// Triangles, unindexed: vertex k of triangle i is p[k][i]. Vertex normals are
/// stored for the triangles that have them (has_normals[i] != 0).
struct TriangleSoA {
    std::vector<Vec3f> p0, p1, p2;
    std::vector<Vec3f> n0, n1, n2;
    std::vector<std::uint8_t> has_normals;
    std::size_t size() const { return p0.size(); }
};

/// NFF cones and cylinders: a truncated cone between base and apex, each end
/// with its own radius, no end caps.
struct ConeSoA {
    std::vector<Vec3f> base, apex;
    std::vector<float> base_radius, apex_radius;  ///< always >= 0
    std::vector<std::uint8_t> inside_only;        ///< NFF negative radii
    std::size_t size() const { return base.size(); }
};

/// What a scene uses, so that the hot loops can skip what it does not.
struct Features {
    bool spheres = false;
    bool triangles = false;
    bool cones = false;
    bool height_fields = false;
    bool vertex_normals = false;
    bool reflection = false;    ///< some material has Ks > 0
    bool transmission = false;  ///< some material has T > 0
    bool colored_lights = false;
    bool inside_only = false;   ///< negative radii
    bool area_lights = false;
    bool distant_lights = false;
    bool glossy = false;        ///< some material has gloss > 0
    bool thin_lens = false;
};

struct Scene {
    std::string source;  ///< file name or gen:NAME:SIZE
    Camera camera;
    bool has_camera = false;
    Vec3f background{0, 0, 0};
    std::vector<PointLight> lights;  ///< point lights (`l`)
    std::vector<AreaLight> area_lights;
    std::vector<DistantLight> distant_lights;
    std::vector<Material> materials;

    SphereSoA spheres;
    TriangleSoA triangles;
    ConeSoA cones;
    /// NFF extension `hf`: each field is one primitive (kernels/height_field.h).
    std::vector<HeightField> height_fields;

    std::vector<PrimRef> prims;                ///< global number -> kind, index
    std::vector<std::uint32_t> prim_material;  ///< global number -> materials[]

    Features features;

    std::size_t primitive_count() const { return prims.size(); }
    /// Lights of every kind: the L of the SPD intensity rule.
    std::size_t light_count() const { return lights.size() + area_lights.size() + distant_lights.size(); }
    /// SPD Readme: each light (and the ambient term) gets sqrt(L) / (2 L).
    float spd_light_intensity() const;

    // Appending keeps the global numbering in definition order.
    std::uint32_t add_sphere(const Vec3f& c, float r, std::uint32_t material);
    std::uint32_t add_triangle(const Vec3f& a, const Vec3f& b, const Vec3f& c, std::uint32_t material);
    std::uint32_t add_triangle(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& na,
                               const Vec3f& nb, const Vec3f& nc, std::uint32_t material);
    std::uint32_t add_cone(const Vec3f& base, float base_r, const Vec3f& apex, float apex_r,
                           std::uint32_t material);
    /// Takes the samples; builds the field's min/max pyramid.
    std::uint32_t add_height_field(HeightField field, std::uint32_t material);
    /// Room for `more` triangles, so that a loader that knows how many
    /// follow does not grow the arrays by copying (fresh pages cost more
    /// than the copies on the measured machines).
    void reserve_triangles(std::size_t more);

    /// Recomputes `features` from the contents; loaders call it last.
    void update_features();
};

/// Bounds of one primitive and of the whole scene.
Box3f primitive_bounds(const Scene& scene, std::uint32_t prim);
Box3f scene_bounds(const Scene& scene);

}  // namespace raypack
