#include "scene/flatten_instances.h"

#include <cmath>
#include <string>

#include "scene/load.h"
#include "scene/memory_budget.h"

namespace raypack {
namespace {

class Flattener {
public:
    Flattener(const Scene& top, Scene& out, std::vector<std::uint32_t>* hit_ids)
        : top_(top), out_(out), hit_ids_(hit_ids) {}

    /// Appends the primitives of `src` (the top scene or an object) placed
    /// by `xf`, whose hit ids start at `id_base`; returns the new numbers of
    /// src's own primitives (instances: the first of their expansion).
    std::vector<std::uint32_t> append(const Scene& src, const Affine3f& xf, bool placed, std::uint32_t id_base) {
        std::vector<std::uint32_t> renumber(src.prims.size());
        const Affine3f normal_xf = affine_cast<float>(inverse(affine_cast<double>(xf)));  // its transpose carries normals
        for (std::uint32_t p = 0; p < src.prims.size(); ++p) {
            const PrimRef ref = src.prims[p];
            const std::uint32_t i = ref.index, m = src.prim_material[p];
            renumber[p] = std::uint32_t(out_.prims.size());
            const std::size_t before = out_.prims.size();
            switch (ref.kind) {
                case PrimKind::Triangle: {
                    const TriangleSoA& t = src.triangles;
                    if (t.has_normals[i])
                        out_.add_triangle(xf.point(t.p0[i]), xf.point(t.p1[i]), xf.point(t.p2[i]),
                                          normal_xf.transposed_vector(t.n0[i]), normal_xf.transposed_vector(t.n1[i]),
                                          normal_xf.transposed_vector(t.n2[i]), m);
                    else
                        out_.add_triangle(xf.point(t.p0[i]), xf.point(t.p1[i]), xf.point(t.p2[i]), m);
                    break;
                }
                case PrimKind::Sphere: {
                    const float s = uniform_scale(xf, placed, "a sphere");
                    const float r = src.spheres.radius[i] * s;
                    out_.add_sphere(xf.point(src.spheres.center[i]), src.spheres.inside_only[i] ? -r : r, m);
                    break;
                }
                case PrimKind::Cone: {
                    const float s = uniform_scale(xf, placed, "a cone"), sign = src.cones.inside_only[i] ? -s : s;
                    out_.add_cone(xf.point(src.cones.base[i]), sign * src.cones.base_radius[i],
                                  xf.point(src.cones.apex[i]), sign * src.cones.apex_radius[i], m);
                    break;
                }
                case PrimKind::HeightField: {
                    HeightField f = src.height_fields[i];
                    if (placed) place_field(f, xf);
                    out_.add_height_field(std::move(f), m);
                    break;
                }
                case PrimKind::Instance: {
                    const Instance& inst = src.instances[i];
                    append(*top_.objects[inst.object], compose(xf, inst.to_world), true,
                           id_base + inst.first_hit_id);
                    continue;  // the nested call named its primitives
                }
            }
            if (hit_ids_ != nullptr)
                for (std::size_t k = before; k < out_.prims.size(); ++k) hit_ids_->push_back(id_base + p);
        }
        return renumber;
    }

private:
    /// The scale of a transform that keeps spheres spheres (M^T M = s^2 I to
    /// float precision); anything else cannot be flattened.
    float uniform_scale(const Affine3f& xf, bool placed, const char* what) const {
        if (!placed) return 1.0f;
        double g[3][3];
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) {
                g[a][b] = 0;
                for (int k = 0; k < 3; ++k) g[a][b] += double(xf.m[k][a]) * double(xf.m[k][b]);
            }
        const double s2 = (g[0][0] + g[1][1] + g[2][2]) / 3;
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                if (std::fabs(g[a][b] - (a == b ? s2 : 0.0)) > 1e-5 * s2)
                    throw SceneError(top_.source, 0, std::string("cannot flatten the instances: ") + what +
                                                         " under a transform that changes its shape");
        return float(std::sqrt(s2));
    }

    /// A field under an axis-aligned positive scale and a translation.
    void place_field(HeightField& f, const Affine3f& xf) const {
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                if ((a == b) != (xf.m[a][b] != 0) || (a == b && xf.m[a][b] < 0))
                    throw SceneError(top_.source, 0, "cannot flatten the instances: a height field under a rotation "
                                                     "or a mirror");
        f.lo = xf.point(f.lo);
        f.hi = xf.point(f.hi);
        for (float& z : f.z) z = xf.m[2][2] * z + xf.m[2][3];
    }

    const Scene& top_;
    Scene& out_;
    std::vector<std::uint32_t>* hit_ids_;
};

}  // namespace

Scene flatten_instances(const Scene& scene, std::vector<std::uint32_t>* hit_ids) {
    if (hit_ids != nullptr) hit_ids->clear();
    if (!scene.moving_instances.empty())
        throw SceneError(scene.source, 0, "cannot flatten the instances: " +
                                              std::to_string(scene.moving_instances.size()) +
                                              " placements move, and a flattened scene is static");
    if (scene.instances.empty()) {
        if (hit_ids != nullptr)
            for (std::uint32_t p = 0; p < scene.prims.size(); ++p) hit_ids->push_back(p);
        return scene;
    }
    require_memory(scene.instanced_primitive_count() * 100,
                   scene.source + ": " + std::to_string(scene.instanced_primitive_count()) + " primitives flattened");
    Scene out;
    out.source = scene.source;
    out.camera = scene.camera;
    out.has_camera = scene.has_camera;
    out.background = scene.background;
    out.lights = scene.lights;
    out.area_lights = scene.area_lights;
    out.distant_lights = scene.distant_lights;
    out.materials = scene.materials;
    const std::vector<std::uint32_t> renumber = Flattener(scene, out, hit_ids).append(scene, Affine3f{}, false, 0);
    for (AreaLight& l : out.area_lights) l.first_prim = renumber[l.first_prim];
    out.update_features();
    return out;
}

}  // namespace raypack
