#include "render/surface.h"

#include "kernels/cone.h"

namespace raypack {

Surface surface_at(const Scene& scene, const Rayf& ray, const Hitf& hit) {
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
            s.geometric_normal = normalize(cross(t.p1[i] - t.p0[i], t.p2[i] - t.p0[i]));
            s.shading_normal = s.geometric_normal;
            if (t.has_normals[i]) {
                const float w = 1.0f - hit.u - hit.v;
                const Vec3f n = t.n0[i] * w + t.n1[i] * hit.u + t.n2[i] * hit.v;
                if (length(n) > 0) s.shading_normal = normalize(n);
            }
            break;
        }
        case PrimKind::Cone:
            s.geometric_normal = normalize(cone_normal(s.point, scene.cones.base[i], scene.cones.base_radius[i],
                                                       scene.cones.apex[i], scene.cones.apex_radius[i]));
            s.shading_normal = s.geometric_normal;
            break;
    }
    return s;
}

}  // namespace raypack
