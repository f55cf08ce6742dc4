#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace raypack {

std::uint32_t Scene::add_sphere(const Vec3f& c, float r, std::uint32_t material) {
    spheres.center.push_back(c);
    spheres.radius.push_back(std::fabs(r));
    spheres.inside_only.push_back(r < 0 ? 1 : 0);
    prims.push_back({PrimKind::Sphere, std::uint32_t(spheres.size() - 1)});
    prim_material.push_back(material);
    return std::uint32_t(prims.size() - 1);
}

std::uint32_t Scene::add_triangle(const Vec3f& a, const Vec3f& b, const Vec3f& c, std::uint32_t material) {
    triangles.p0.push_back(a);
    triangles.p1.push_back(b);
    triangles.p2.push_back(c);
    triangles.n0.push_back({});
    triangles.n1.push_back({});
    triangles.n2.push_back({});
    triangles.has_normals.push_back(0);
    prims.push_back({PrimKind::Triangle, std::uint32_t(triangles.size() - 1)});
    prim_material.push_back(material);
    return std::uint32_t(prims.size() - 1);
}

std::uint32_t Scene::add_triangle(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& na,
                                  const Vec3f& nb, const Vec3f& nc, std::uint32_t material) {
    const std::uint32_t id = add_triangle(a, b, c, material);
    const std::size_t i = triangles.size() - 1;
    triangles.n0[i] = na;
    triangles.n1[i] = nb;
    triangles.n2[i] = nc;
    triangles.has_normals[i] = 1;
    return id;
}

void Scene::reserve_triangles(std::size_t more) {
    const std::size_t n = triangles.size() + more;
    for (auto* v : {&triangles.p0, &triangles.p1, &triangles.p2, &triangles.n0, &triangles.n1, &triangles.n2})
        v->reserve(n);
    triangles.has_normals.reserve(n);
    prims.reserve(prims.size() + more);
    prim_material.reserve(prim_material.size() + more);
}

std::uint32_t Scene::add_cone(const Vec3f& base, float base_r, const Vec3f& apex, float apex_r,
                              std::uint32_t material) {
    cones.base.push_back(base);
    cones.apex.push_back(apex);
    cones.base_radius.push_back(std::fabs(base_r));
    cones.apex_radius.push_back(std::fabs(apex_r));
    cones.inside_only.push_back(base_r < 0 && apex_r < 0 ? 1 : 0);
    prims.push_back({PrimKind::Cone, std::uint32_t(cones.size() - 1)});
    prim_material.push_back(material);
    return std::uint32_t(prims.size() - 1);
}

std::uint32_t Scene::add_height_field(HeightField field, std::uint32_t material) {
    field.build_ranges();
    height_fields.push_back(std::move(field));
    prims.push_back({PrimKind::HeightField, std::uint32_t(height_fields.size() - 1)});
    prim_material.push_back(material);
    return std::uint32_t(prims.size() - 1);
}

std::uint32_t Scene::add_instance(std::uint32_t object, const Affine3f& to_world, const Scene& top) {
    Instance inst;
    inst.object = object;
    inst.to_world = to_world;
    inst.to_object = affine_cast<float>(inverse(affine_cast<double>(to_world)));
    inst.bounds = transform_box(to_world, scene_bounds(*top.objects[object]));
    instances.push_back(inst);
    prims.push_back({PrimKind::Instance, std::uint32_t(instances.size() - 1)});
    prim_material.push_back(0);  // never read: hits name the primitives inside
    return std::uint32_t(prims.size() - 1);
}

Affine3f Instance::to_world_at(float s) const {
    // (1 - s) a + s b: exactly to_world at 0 and to_world_end at 1.
    Affine3f r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = (1.0f - s) * to_world.m[i][j] + s * to_world_end.m[i][j];
    return r;
}

Affine3f Instance::to_object_at(float s) const {
    if (s == 0.0f) return to_object;
    if (translates_only) {
        // p = A q + b(s)  =>  q = A^-1 p - A^-1 b(s).
        Affine3f r = to_object;
        Vec3f b;
        for (int i = 0; i < 3; ++i) b[i] = (1.0f - s) * to_world.m[i][3] + s * to_world_end.m[i][3];
        const Vec3f t = to_object.vector(b);
        r.m[0][3] = -t.x, r.m[1][3] = -t.y, r.m[2][3] = -t.z;
        return r;
    }
    return affine_cast<float>(inverse(affine_cast<double>(to_world_at(s))));
}

std::uint32_t Scene::add_moving_instance(std::uint32_t object, const Affine3f& to_world, const Affine3f& to_world_end,
                                         const Scene& top) {
    Instance inst;
    inst.object = object;
    inst.to_world = to_world;
    inst.to_object = affine_cast<float>(inverse(affine_cast<double>(to_world)));
    inst.to_world_end = to_world_end;
    inst.translates_only = true;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) inst.translates_only &= to_world.m[i][j] == to_world_end.m[i][j];
    const Box3f object_box = scene_bounds(*top.objects[object]);
    inst.bounds_start = transform_box(to_world, object_box);
    inst.bounds_end = transform_box(to_world_end, object_box);
    inst.bounds = inst.bounds_start;
    inst.bounds.extend(inst.bounds_end);
    moving_instances.push_back(inst);
    return std::uint32_t(moving_instances.size() - 1);
}

void Scene::update_features(const Scene* top) {
    if (top == nullptr) top = this;
    const auto& top_materials = top->materials;
    Features f;
    f.spheres = spheres.size() > 0;
    f.triangles = triangles.size() > 0;
    f.cones = cones.size() > 0;
    f.height_fields = !height_fields.empty();
    for (auto h : triangles.has_normals) f.vertex_normals |= h != 0;
    for (auto h : spheres.inside_only) f.inside_only |= h != 0;
    for (auto h : cones.inside_only) f.inside_only |= h != 0;
    for (std::size_t p = 0; p < prims.size(); ++p) {
        if (prims[p].kind == PrimKind::Instance) continue;
        const std::uint32_t m = prim_material[p];
        f.reflection |= top_materials[m].ks > 0;
        f.transmission |= top_materials[m].transmittance > 0;
        f.glossy |= top_materials[m].gloss > 0;
    }
    for (const auto& l : lights) f.colored_lights |= l.has_color;
    for (const auto& l : area_lights) f.colored_lights |= l.has_color;
    for (const auto& l : distant_lights) f.colored_lights |= l.has_color;
    f.area_lights = !area_lights.empty();
    f.distant_lights = !distant_lights.empty();
    f.thin_lens = camera.lens_radius > 0;
    f.instances = placements();
    f.motion = !moving_instances.empty();
    // Ids of instanced hits follow the scene's own primitives, instance by
    // instance, the moving ones last (Scene::hit_id_count); objects report
    // what they contain.
    hit_ids_ = prims.size();
    instanced_prims_ = prims.size() - instances.size();
    instance_depth_ = 0;
    const auto place = [&](Instance& inst) {
        const Scene& o = *top->objects[inst.object];
        inst.first_hit_id = std::uint32_t(std::min<std::uint64_t>(hit_ids_, kMaxHitIds));
        hit_ids_ += o.hit_id_count();
        instanced_prims_ += o.instanced_primitive_count();
        instance_depth_ = std::max(instance_depth_, 1 + o.instance_depth());
        const Features& g = o.features;
        f.spheres |= g.spheres, f.triangles |= g.triangles, f.cones |= g.cones;
        f.height_fields |= g.height_fields, f.instances |= g.instances;
        f.vertex_normals |= g.vertex_normals, f.inside_only |= g.inside_only;
        f.reflection |= g.reflection, f.transmission |= g.transmission, f.glossy |= g.glossy;
    };
    for (Instance& inst : instances) place(inst);
    for (Instance& inst : moving_instances) place(inst);
    features = f;
}

float AreaLight::area() const {
    if (shape == AreaLightShape::Sphere) return 4.0f * std::numbers::pi_v<float> * radius * radius;
    return length(cross(edge1, edge2));
}

float Scene::spd_light_intensity() const {
    const float n = float(std::max<std::size_t>(light_count(), 1));
    return std::sqrt(n) / (2.0f * n);
}

Box3f primitive_bounds(const Scene& s, std::uint32_t prim) {
    const PrimRef ref = s.prims[prim];
    Box3f b;
    const std::uint32_t i = ref.index;
    switch (ref.kind) {
        case PrimKind::Sphere: {
            const float r = s.spheres.radius[i];
            b.extend(s.spheres.center[i] - Vec3f{r, r, r});
            b.extend(s.spheres.center[i] + Vec3f{r, r, r});
            break;
        }
        case PrimKind::Triangle:
            b.extend(s.triangles.p0[i]);
            b.extend(s.triangles.p1[i]);
            b.extend(s.triangles.p2[i]);
            break;
        case PrimKind::Instance: b = s.instances[i].bounds; break;
        case PrimKind::HeightField:
            b.extend(s.height_fields[i].lo);
            b.extend(s.height_fields[i].hi);
            break;
        case PrimKind::Cone: {
            // Each end is a disc; its box extent along axis a is r * sqrt(1 - n_a^2).
            const Vec3f ends[2] = {s.cones.base[i], s.cones.apex[i]};
            const float radii[2] = {s.cones.base_radius[i], s.cones.apex_radius[i]};
            const Vec3f axis = normalize(ends[1] - ends[0]);
            for (int e = 0; e < 2; ++e) {
                Vec3f ext;
                for (int a = 0; a < 3; ++a)
                    ext[a] = radii[e] * std::sqrt(std::max(0.0f, 1.0f - axis[a] * axis[a])) * 1.0001f;  // pad for rounding
                b.extend(ends[e] - ext);
                b.extend(ends[e] + ext);
            }
            break;
        }
    }
    return b;
}

Box3f scene_bounds(const Scene& s) {
    Box3f b;
    for (std::uint32_t i = 0; i < s.prims.size(); ++i) b.extend(primitive_bounds(s, i));
    for (const Instance& inst : s.moving_instances) b.extend(inst.bounds);
    return b;
}

const Instance& instance_of_hit_id(const Scene& scene, std::uint32_t id) {
    // The last instance whose ids start at or before id; moving instances'
    // ids follow the static ones'.
    const bool moving = !scene.moving_instances.empty() && id >= scene.moving_instances.front().first_hit_id;
    const std::vector<Instance>& list = moving ? scene.moving_instances : scene.instances;
    const auto it = std::upper_bound(list.begin(), list.end(), id,
                                     [](std::uint32_t x, const Instance& k) { return x < k.first_hit_id; });
    return *(it - 1);
}

HitInPlacement hit_in_placement(const Scene& scene, const Rayf& ray, const Hitf& hit, float time) {
    const Instance& inst = instance_of_hit_id(scene, hit.prim);
    Hitf h = hit;
    h.prim -= inst.first_hit_id;
    HitInPlacement in{&inst, inst.to_world, inst.to_object, {}, h};
    // Moving placements' ids follow the static ones' (instance_of_hit_id).
    if (!scene.moving_instances.empty() && hit.prim >= scene.moving_instances.front().first_hit_id) {
        const float s = scene.shutter_fraction(time);
        in.to_world = inst.to_world_at(s);
        in.to_object = inst.to_object_at(s);
    }
    in.ray = ray_in_object(in.to_object, ray);
    return in;
}

ResolvedHit resolve_hit_id(const Scene& top, std::uint32_t id, float time) {
    ResolvedHit r;
    const Scene* s = &top;
    while (id >= s->prims.size() && s->placements()) {
        const HitInPlacement in = hit_in_placement(*s, Rayf{}, Hitf{0, id}, time);
        const Instance& inst = *in.instance;
        id -= inst.first_hit_id;
        r.to_world = r.instanced ? compose(r.to_world, in.to_world) : in.to_world;
        r.to_object = r.instanced ? compose(in.to_object, r.to_object) : in.to_object;
        r.instanced = true;
        s = top.objects[inst.object].get();
    }
    r.scene = s;
    r.prim = id;
    return r;
}

}  // namespace raypack
