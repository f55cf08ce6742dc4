#pragma once
// The scene as structure of arrays: one set of arrays per primitive kind,
// plus a global numbering of primitives in the order the file defines them.
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "kernels/aabb.h"
#include "kernels/affine.h"
#include "kernels/height_field.h"
#include "kernels/ray.h"

namespace raypack {

enum class PrimKind : std::uint8_t { Sphere, Triangle, Cone, HeightField, Instance };

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

/// NFF extension `inst NAME m00 .. m23`: object `object` (an index into the
/// top scene's Scene::objects) placed by `to_world`. Hits inside it are
/// numbered from `first_hit_id` on in the id space of the scene that holds
/// the instance (see Scene::hit_id_count).
struct Instance {
    std::uint32_t object = 0;
    Affine3f to_world, to_object;  ///< to_object is the inverse of to_world
    Box3f bounds;                  ///< world bounds of the placed object (over the whole shutter if it moves)
    std::uint32_t first_hit_id = 0;
    /// Motion (Scene::moving_instances only): the object sits at
    /// (1 - s) to_world + s to_world_end at shutter fraction s, the matrices
    /// interpolated entry by entry as Embree interpolates an instance's
    /// time steps. Every point then moves on a straight line, so the box at
    /// s lies within the same interpolation of the boxes at 0 and 1.
    Affine3f to_world_end;
    Box3f bounds_start, bounds_end;
    /// The linear parts at both ends are the same (a `move`): in between
    /// the inverse is to_object's linear part with a new translation.
    bool translates_only = false;

    /// The placement at shutter fraction s in [0, 1] (moving instances).
    Affine3f to_world_at(float s) const;
    /// Its inverse, computed in double like to_object.
    Affine3f to_object_at(float s) const;
};

/// What a scene uses, so that the hot loops can skip what it does not.
struct Features {
    bool spheres = false;
    bool triangles = false;
    bool cones = false;
    bool height_fields = false;
    bool instances = false;
    bool motion = false;        ///< moving placements (NFF `move`, two-matrix `inst`)
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
    /// NFF extension `inst`: each placement is one primitive.
    std::vector<Instance> instances;
    /// NFF extension `begin NAME` ... `end`: the objects that instances place,
    /// in definition order (an object only places objects defined before it,
    /// so there are no cycles). Only the top scene holds them; an object's own
    /// instances index the top scene's list. Materials are the top scene's.
    std::vector<std::shared_ptr<const Scene>> objects;
    std::vector<std::string> object_names;
    /// NFF extensions `move` and two-matrix `inst`: placements that move over
    /// the shutter. Not primitives (no entry in `prims`): the structures over
    /// `prims` stay static, and build_accel puts these in a motion BVH
    /// (accel/motion/motion_bvh.h). Their hit ids follow the static
    /// instances'. Only the top scene moves: objects are static.
    std::vector<Instance> moving_instances;
    /// NFF extension `shutter t0 t1`: the times rays may carry (ray time t
    /// is shutter fraction (t - t0) / (t1 - t0), clamped to [0, 1]).
    float shutter_open = 0, shutter_close = 1;
    /// Shutter fraction of scene time `time`: 0 at or before the opening
    /// (also for -inf, "no time", and NaN), 1 at or after the closing, and 0
    /// for a shutter of no length (t0 = t1 freezes every motion at t0).
    float shutter_fraction(float time) const {
        const float length = shutter_close - shutter_open;
        if (!(length > 0) || !(time > shutter_open)) return 0.0f;
        const float s = (time - shutter_open) / length;
        return s < 1.0f ? s : 1.0f;
    }

    std::vector<PrimRef> prims;                ///< global number -> kind, index
    std::vector<std::uint32_t> prim_material;  ///< global number -> materials[]

    Features features;

    std::size_t primitive_count() const { return prims.size(); }
    /// Hit ids (Hit::prim) run over [0, hit_id_count()): the scene's own
    /// primitives keep their numbers (an instance's own number is never a
    /// hit), and instance k's hits are first_hit_id + the id inside its
    /// object, which past the object's own primitives recurses the same way.
    /// Without instances it is primitive_count().
    std::uint64_t hit_id_count() const { return placements() ? hit_ids_ : prims.size(); }
    /// Primitives once every instance is expanded (instances themselves not
    /// counted): what the scene would hold flattened.
    std::uint64_t instanced_primitive_count() const { return placements() ? instanced_prims_ : prims.size(); }
    /// Levels of placements below this scene: 0 without instances, else 1 +
    /// the deepest placed object's.
    int instance_depth() const { return placements() ? instance_depth_ : 0; }
    /// Whether the scene places objects (static or moving).
    bool placements() const { return !instances.empty() || !moving_instances.empty(); }
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
    /// Places objects[object] under `to_world`, which must be finite and
    /// invertible (the loader checks); `top` holds the objects (it may be
    /// this scene). Call update_features before tracing: it numbers the hit ids.
    std::uint32_t add_instance(std::uint32_t object, const Affine3f& to_world, const Scene& top);
    /// A placement moving from `to_world` at the shutter's opening to
    /// `to_world_end` at its closing; both finite, and every interpolation
    /// between them invertible (the loader checks). Returns its index in
    /// moving_instances.
    std::uint32_t add_moving_instance(std::uint32_t object, const Affine3f& to_world, const Affine3f& to_world_end,
                                      const Scene& top);
    /// Room for `more` triangles, so that a loader that knows how many
    /// follow does not grow the arrays by copying (fresh pages cost more
    /// than the copies on the measured machines).
    void reserve_triangles(std::size_t more);

    /// Recomputes `features` and the hit id numbering from the contents;
    /// loaders call it last (and on each object when its definition ends).
    /// `top` is the scene whose objects and materials this one uses (null:
    /// this scene itself).
    void update_features(const Scene* top = nullptr);

private:
    std::uint64_t hit_ids_ = 0, instanced_prims_ = 0;
    int instance_depth_ = 0;
};

/// Deepest nesting of placements a scene may have: each level is a nested
/// traversal on the stack (and a transform of every ray that reaches it).
inline constexpr int kMaxInstanceDepth = 32;

/// Hit ids past this are not representable (kNoPrim is the miss).
inline constexpr std::uint64_t kMaxHitIds = 0xFFFFFFFFull;

/// A hit id resolved to the primitive it names: `scene` holds it (the top
/// scene or an object), `prim` is its number there, and `to_world` carries
/// that scene's space to the top scene's (the composition of the instances
/// on the way; the identity for the top scene's own primitives).
struct ResolvedHit {
    const Scene* scene = nullptr;
    std::uint32_t prim = 0;
    Affine3f to_world, to_object;
    bool instanced = false;
};
ResolvedHit resolve_hit_id(const Scene& top, std::uint32_t id, float time = -std::numeric_limits<float>::infinity());

/// The instance of `scene` (static or moving) whose hit ids hold `id` (id >= prims.size()).
const Instance& instance_of_hit_id(const Scene& scene, std::uint32_t id);

/// A ray in an instance's object space, as the traversal takes it there
/// (the direction not renormalised, so t is unchanged).
inline Rayf ray_in_object(const Affine3f& to_object, const Rayf& ray) {
    return {to_object.point(ray.org), to_object.vector(ray.dir), ray.tnear, ray.tfar};
}
inline Rayf ray_in_object(const Instance& inst, const Rayf& ray) { return ray_in_object(inst.to_object, ray); }

/// A hit inside one of `scene`'s placements, one level down: the
/// placement (where it is at the ray's time), the ray in its object's
/// space and the hit with its id there. `time` is scene time (-inf: the
/// shutter's opening); only moving placements depend on it.
struct HitInPlacement {
    const Instance* instance;
    Affine3f to_world, to_object;
    Rayf ray;
    Hitf hit;
};
HitInPlacement hit_in_placement(const Scene& scene, const Rayf& ray, const Hitf& hit,
                                float time = -std::numeric_limits<float>::infinity());

/// Bounds of one primitive and of the whole scene.
Box3f primitive_bounds(const Scene& scene, std::uint32_t prim);
Box3f scene_bounds(const Scene& scene);

}  // namespace raypack
