#include "render/surface.h"

#include "kernels/cone.h"

namespace raypack {

namespace {

/// The unit geometric normal of triangle i, as surface_at computes it.
Vec3f triangle_normal(const TriangleSoA& t, std::uint32_t i) {
    return normalize(cross(t.p1[i] - t.p0[i], t.p2[i] - t.p0[i]));
}

/// surface_at in `scene` (the top scene or an object) of the top scene
/// `top`; `mirrored`: the instances on the way turn space inside out, so a
/// triangle's winding normal flips as the flattened triangle's would.
Surface surface_in(const Scene& top, const Scene& scene, const Rayf& ray, const Hitf& hit, bool mirrored,
                   float time) {
    if (hit.prim >= scene.prims.size()) {
        // An instanced primitive: its surface in object space (the ray taken
        // there as the traversal took it), normals back with the inverse
        // transpose (Scene::hit_id_count, accel/prims/instance_prims.h).
        const HitInPlacement in = hit_in_placement(scene, ray, hit, time);
        const bool flip = in.to_world.determinant() < 0;
        const Surface o = surface_in(top, *top.objects[in.instance->object], in.ray, in.hit, mirrored != flip, time);
        Surface w;
        w.point = ray.org + ray.dir * hit.t;
        w.material = o.material;
        w.geometric_normal = normalize(in.to_object.transposed_vector(o.geometric_normal));
        w.shading_normal = normalize(in.to_object.transposed_vector(o.shading_normal));
        return w;
    }
    Surface s;
    s.point = ray.org + ray.dir * hit.t;
    s.material = scene.prim_material[hit.prim];
    const PrimRef ref = scene.prims[hit.prim];
    const std::uint32_t i = ref.index;
    switch (ref.kind) {
        case PrimKind::Sphere:
            // From the centre; exact for the normal direction even if the
            // hit point is slightly off the surface.
            s.geometric_normal = normalize(s.point - scene.spheres.center[i]);
            s.shading_normal = s.geometric_normal;
            break;
        case PrimKind::Triangle: {
            const TriangleSoA& t = scene.triangles;
            s.geometric_normal = mirrored ? -triangle_normal(t, i) : triangle_normal(t, i);
            s.shading_normal = t.has_normals[i] ? smooth_normal(t, i, hit, s.geometric_normal) : s.geometric_normal;
            break;
        }
        case PrimKind::Instance: break;  // never a hit id: hits inside carry their own
        case PrimKind::HeightField:
            s.geometric_normal = normalize(height_field_normal(scene.height_fields[i], hit.u, hit.v));
            s.shading_normal = s.geometric_normal;
            break;
        case PrimKind::Cone:
            s.geometric_normal = normalize(cone_normal(s.point, scene.cones.base[i], scene.cones.base_radius[i],
                                                       scene.cones.apex[i], scene.cones.apex_radius[i]));
            s.shading_normal = s.geometric_normal;
            break;
    }
    return s;
}

}  // namespace

Surface surface_at(const Scene& scene, const Rayf& ray, const Hitf& hit, float time) {
    return surface_in(scene, scene, ray, hit, false, time);
}


SurfaceTable::SurfaceTable(const Scene& scene) : scene_(scene), records_(scene.prims.size()) {
    for (std::size_t p = 0; p < records_.size(); ++p) {
        const PrimRef ref = scene.prims[p];
        Record& r = records_[p];
        Kind kind = kOther;
        if (ref.kind == PrimKind::Triangle) {
            r.v = triangle_normal(scene.triangles, ref.index);
            kind = scene.triangles.has_normals[ref.index] ? kSmoothTriangle : kFlatTriangle;
        } else if (ref.kind == PrimKind::Sphere) {
            r.v = scene.spheres.center[ref.index];
            kind = kSphere;
        } else if (ref.kind == PrimKind::Cone) {
            kind = kCone;  // SurfaceLanes reads the cone's ends and radii
        }
        r.material_kind = scene.prim_material[p] << kKindBits | kind;
    }
}

}  // namespace raypack
