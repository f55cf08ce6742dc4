#pragma once
// The shaded points of one wavefront level, one array per coordinate, so
// that the light of a point light reaches many points at once in SIMD
// lanes (render/point_light_shading.cpp).
#include <cstdint>
#include <span>
#include <vector>

#include "kernels/ray.h"
#include "render/append_buffer.h"
#include "render/sampler.h"
#include "scene/scene.h"

namespace raypack {

class RayOffset;

class ShadingPoints {
public:
    /// Lanes read past the last point (and masked off): the arrays keep this
    /// many spare entries, so that no load runs off their end.
    static constexpr std::size_t kSpare = 16;

    std::size_t size() const { return count_; }
    void clear() { count_ = 0; }

    /// A point shading ray-tree entry `ray`: `view` the unit direction the
    /// ray arrives along, `ns` and `ng` the shading and geometric normals
    /// (both turned toward the viewer), `above` where rays toward the
    /// viewer's side leave the surface, and the material's Phong terms.
    void add(std::int32_t ray, const Vec3f& view, const Vec3f& ns, const Vec3f& ng, const Vec3f& above,
             const Material& m, float specular_cutoff);

    /// The columns from the next point on, writable for kSpare points: the
    /// SIMD surface loop writes a block of points in place, whole vectors
    /// (entries past the block are written over by the next one), then
    /// commit(n) takes n of them, n <= kSpare.
    struct Block {
        std::int32_t* ray;
        float *view[3], *ns[3], *ng[3], *above[3], *color[3];
        float *kd, *ks, *shine, *cutoff;
    };
    Block next_block();
    void commit(std::size_t n) { count_ += n; }

    std::int32_t ray(std::size_t j) const { return ray_[j]; }
    Vec3f view(std::size_t j) const { return get(view_, j); }
    Vec3f shading_normal(std::size_t j) const { return get(ns_, j); }
    Vec3f geometric_normal(std::size_t j) const { return get(ng_, j); }
    Vec3f above(std::size_t j) const { return get(above_, j); }

private:
    friend struct LightLanes;
    friend struct PointLightLanes;
    friend struct AreaLightLanes;
    std::size_t count_ = 0;
    std::vector<std::int32_t> ray_;
    std::vector<float> view_[3], ns_[3], ng_[3], above_[3], color_[3];
    std::vector<float> kd_, ks_, shine_, cutoff_;

    static Vec3f get(const std::vector<float> (&a)[3], std::size_t j) { return {a[0][j], a[1][j], a[2][j]}; }
    void grow();
};

/// Shadow rays toward one light, each with the ray-tree entry it lights and
/// the light's contribution there should it be unoccluded.
struct ShadowQueue {
    AppendBuffer<Rayf> rays;
    AppendBuffer<std::int32_t> owner;
    AppendBuffer<Vec3f> contribution;

    /// n more rays, each with its owner and contribution: the caller writes them.
    struct Run {
        Rayf* rays;
        std::int32_t* owner;
        Vec3f* contribution;
    };
    Run append(std::size_t n) { return {rays.append(n), owner.append(n), contribution.append(n)}; }

    void clear() {
        rays.clear();
        owner.clear();
        contribution.clear();
    }
};

/// How a point light's intensity falls off: 1 / (c2 r^2 + c1 r + c0).
struct Attenuation {
    float c0 = 1, c1 = 0, c2 = 0;
};

/// For every point that faces `light` with both normals (the SPD protocol:
/// no shadow ray otherwise), appends in point order a shadow ray toward the
/// light and its Lambert plus Phong light, the light's colour scaled by
/// `intensity` and the attenuation. Returns the number of rays appended.
/// Bit for bit what the scalar expressions of the recursive tracer give
/// (tests/test_render_identity.cpp): the lanes do the same operations in the
/// same order, phong_power included.
std::size_t shade_point_light(const ShadingPoints& points, const PointLight& light, float intensity,
                              const Attenuation& attenuation, const RayOffset& offset, ShadowQueue& out);

/// For every point and each of `samples` points on area `light` (point j's
/// sample k drawn from the unit-square point drawn[j * samples + k]; a
/// sphere's facing point instead if `facing_point`), appends point by point
/// and sample by sample a shadow ray toward the light's point and its
/// Lambert plus Phong light (the light's colour times intensity / samples),
/// where the point lies on the emitting side and both normals face it.
/// Returns the number of rays appended. Bit for bit the scalar expressions
/// (render/area_light_shading.cpp).
std::size_t shade_area_light(const ShadingPoints& points, const AreaLight& light, std::span<const Sample2> drawn,
                             int samples, float intensity, bool facing_point, const RayOffset& offset,
                             ShadowQueue& out);

}  // namespace raypack
