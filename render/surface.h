#pragma once
// What shading needs to know about a hit: position, normals, material.
#include <limits>
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

/// Surface at a found hit of `ray` at scene time `time` (-inf: the
/// shutter's opening; only moving placements depend on it).
Surface surface_at(const Scene& scene, const Rayf& ray, const Hitf& hit, float time = -std::numeric_limits<float>::infinity());

/// The interpolated normal of triangle i at the hit's barycentrics, or the
/// geometric normal `ng` where it vanishes (surface_at's shading normal).
/// Inline: as a call it was 3% of a Whitted render of the teapot.
inline Vec3f smooth_normal(const TriangleSoA& t, std::uint32_t i, const Hitf& hit, const Vec3f& ng) {
    const float w = 1.0f - hit.u - hit.v;
    const Vec3f n = t.n0[i] * w + t.n1[i] * hit.u + t.n2[i] * hit.v;
    return length(n) > 0 ? normalize(n) : ng;
}

/// surface_at's answers, bit for bit, from one 16-byte record per primitive
/// (a triangle's unit normal or a sphere's centre, with the material):
/// hits of secondary rays land anywhere in the scene, and surface_at's reads
/// of the material, the primitive table and three vertex arrays missed the
/// cache (8% of a path-traced bunny). Built once per render.
template <int K>
struct SurfaceLanes;  // render/surface_lanes.h

class SurfaceTable {
public:
    explicit SurfaceTable(const Scene& scene);
    /// Inline: out of line, the returned Surface went through the stack and
    /// its copy stalled on store forwarding in the shading loops.
    Surface at(const Rayf& ray, const Hitf& hit, float time = -std::numeric_limits<float>::infinity()) const;

private:
    template <int K>
    friend struct SurfaceLanes;
    enum Kind : std::uint32_t { kFlatTriangle, kSmoothTriangle, kSphere, kCone, kOther };
    static constexpr std::uint32_t kKindBits = 3, kKindMask = (1u << kKindBits) - 1;
    struct Record {
        Vec3f v;                     ///< triangle: unit geometric normal; sphere: centre
        std::uint32_t material_kind;  ///< material << kKindBits | Kind
    };
    static_assert(sizeof(Record) == 16);
    const Scene& scene_;
    std::vector<Record> records_;
};

inline Surface SurfaceTable::at(const Rayf& ray, const Hitf& hit, float time) const {
    if (hit.prim >= records_.size()) return surface_at(scene_, ray, hit, time);  // inside an instance
    // Field by field from the table: a copy of the whole record went
    // through the stack and its 4-byte reads stalled on the 16-byte store
    // (store forwarding; 14% of the surface loop's samples).
    const Record& r = records_[hit.prim];
    const std::uint32_t material_kind = r.material_kind;
    Surface s;
    s.point = ray.org + ray.dir * hit.t;
    s.material = material_kind >> kKindBits;
    switch (Kind(material_kind & kKindMask)) {
        case kFlatTriangle:
            s.geometric_normal = s.shading_normal = r.v;
            return s;
        case kSmoothTriangle:
            s.geometric_normal = r.v;
            s.shading_normal = smooth_normal(scene_.triangles, scene_.prims[hit.prim].index, hit, r.v);
            return s;
        case kSphere:
            s.geometric_normal = s.shading_normal = normalize(s.point - r.v);
            return s;
        case kCone:
        case kOther: break;
    }
    return surface_at(scene_, ray, hit);
}

}  // namespace raypack
