#pragma once
// What shading needs to know about a hit: position, normals, material.
#include <vector>

#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

struct Surface {
    Vec3f point;
    Vec3f geometric_normal;  ///< unit, the primitive's own orientation (outward for spheres and cones)
    Vec3f shading_normal;    ///< unit, interpolated for triangles with vertex normals
    std::uint32_t material = 0;
};

/// Surface at a found hit of `ray`.
Surface surface_at(const Scene& scene, const Rayf& ray, const Hitf& hit);

/// surface_at's answers, bit for bit, from one 16-byte record per primitive
/// (a triangle's unit normal or a sphere's centre, with the material):
/// hits of secondary rays land anywhere in the scene, and surface_at's reads
/// of the material, the primitive table and three vertex arrays missed the
/// cache (8% of a path-traced bunny). Built once per render.
class SurfaceTable {
public:
    explicit SurfaceTable(const Scene& scene);
    Surface at(const Rayf& ray, const Hitf& hit) const;

private:
    enum Kind : std::uint32_t { kFlatTriangle, kSmoothTriangle, kSphere, kOther };
    struct Record {
        Vec3f v;                     ///< triangle: unit geometric normal; sphere: centre
        std::uint32_t material_kind;  ///< material << 2 | Kind
    };
    static_assert(sizeof(Record) == 16);
    const Scene& scene_;
    std::vector<Record> records_;
};

}  // namespace raypack
