#include "scene/height_field_mesh.h"

#include "scene/memory_budget.h"

namespace raypack {

namespace {

/// `scene` with its fields as triangles, and `objects` as its objects (the
/// converted ones for the top scene; none for an object).
Scene convert(const Scene& scene, const std::vector<std::shared_ptr<const Scene>>& objects) {
    std::size_t triangles = scene.triangles.size();
    for (const HeightField& f : scene.height_fields) triangles += 2 * std::size_t(f.cells_x()) * f.cells_y();
    require_memory(std::uint64_t(triangles) * 80, scene.source + ": height fields as " +
                                                          std::to_string(triangles) + " triangles");
    Scene out = scene;
    out.spheres = {};
    out.triangles = {};
    out.cones = {};
    out.height_fields = {};
    out.instances = {};
    out.objects = objects;
    out.prims.clear();
    out.prim_material.clear();
    out.reserve_triangles(triangles);
    // Area lights name the primitives of their surfaces; they are spheres or
    // parallelograms, never fields, but numbers after a field shift.
    std::vector<std::uint32_t> renumber(scene.prims.size());
    for (std::uint32_t p = 0; p < scene.prims.size(); ++p) {
        const PrimRef ref = scene.prims[p];
        const std::uint32_t i = ref.index, m = scene.prim_material[p];
        renumber[p] = std::uint32_t(out.prims.size());
        switch (ref.kind) {
            case PrimKind::Sphere: {
                const float r = scene.spheres.radius[i];
                out.add_sphere(scene.spheres.center[i], scene.spheres.inside_only[i] ? -r : r, m);
                break;
            }
            case PrimKind::Triangle: {
                const TriangleSoA& t = scene.triangles;
                if (t.has_normals[i]) out.add_triangle(t.p0[i], t.p1[i], t.p2[i], t.n0[i], t.n1[i], t.n2[i], m);
                else out.add_triangle(t.p0[i], t.p1[i], t.p2[i], m);
                break;
            }
            case PrimKind::Cone: {
                const ConeSoA& c = scene.cones;
                const float sign = c.inside_only[i] ? -1.0f : 1.0f;
                out.add_cone(c.base[i], sign * c.base_radius[i], c.apex[i], sign * c.apex_radius[i], m);
                break;
            }
            case PrimKind::Instance:
                out.instances.push_back(scene.instances[i]);
                out.prims.push_back({PrimKind::Instance, std::uint32_t(out.instances.size() - 1)});
                out.prim_material.push_back(m);
                break;
            case PrimKind::HeightField: {
                const HeightField& f = scene.height_fields[i];
                auto point = [&](std::uint32_t a, std::uint32_t b) {
                    return Vec3f{f.lo.x + (f.hi.x - f.lo.x) * float(a) / float(f.cells_x()),
                                 f.lo.y + (f.hi.y - f.lo.y) * float(b) / float(f.cells_y()), f.sample(a, b)};
                };
                for (std::uint32_t b = 0; b < f.cells_y(); ++b)
                    for (std::uint32_t a = 0; a < f.cells_x(); ++a) {
                        const Vec3f p00 = point(a, b), p10 = point(a + 1, b), p01 = point(a, b + 1),
                                    p11 = point(a + 1, b + 1);
                        out.add_triangle(p00, p10, p11, m);
                        out.add_triangle(p00, p11, p01, m);
                    }
                break;
            }
        }
    }
    for (AreaLight& l : out.area_lights) l.first_prim = renumber[l.first_prim];
    return out;
}

}  // namespace

Scene height_fields_as_triangles(const Scene& scene) {
    bool any = !scene.height_fields.empty();
    for (const auto& o : scene.objects) any |= o->features.height_fields;
    if (!any) return scene;
    // Objects first (their fields too), in order: an object's instances
    // count the ids of the converted objects before it.
    Scene top_view;  // what the objects' numbering reads: the converted objects and the materials
    top_view.materials = scene.materials;
    for (const auto& o : scene.objects) {
        auto converted = std::make_shared<Scene>(convert(*o, {}));
        converted->update_features(&top_view);
        top_view.objects.push_back(std::move(converted));
    }
    Scene out = convert(scene, top_view.objects);
    out.update_features();
    return out;
}

}  // namespace raypack
