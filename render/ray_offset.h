#pragma once
// Where a secondary ray starts: the hit point moved off the surface so that
// the new ray does not find the surface it left (self-intersection, "surface
// acne"). Three policies, selectable with --offset, compared by
// `raypack bench --tradeoff` (docs/accuracy.md).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "kernels/ray.h"
#include "render/surface.h"
#include "scene/scene.h"

namespace raypack {

enum class OffsetPolicy {
    Epsilon,  ///< a fixed 1e-4 along the normal, whatever the scene's size
    Scaled,   ///< 1e-4 x max(|p|, 1e-3 x scene extent): relative to the magnitude
    Robust,   ///< Waechter & Binder, Ray Tracing Gems ch. 6: 256 ULPs of each coordinate,
              ///< near the origin thresholds in units of the scene extent
};

/// What render, rays and bench use without --offset.
inline constexpr OffsetPolicy kDefaultOffset = OffsetPolicy::Scaled;

/// "epsilon" | "scaled" | "robust".
const char* offset_policy_name(OffsetPolicy policy);
std::optional<OffsetPolicy> parse_offset_policy(const std::string& name);
/// The names joined by '|', for help and error messages.
std::string offset_policy_list();

/// The hit point as accurately as float allows: for triangles from the
/// barycentrics (the vertices carry no error, org + t dir carries the error
/// of t times |dir|), for spheres org + t dir projected back onto the sphere,
/// for cones org + t dir (Waechter & Binder, RTG ch. 6.2). `time`: the
/// ray's scene time (surface_at).
Vec3f accurate_hit_point(const Scene& scene, const Rayf& ray, const Hitf& hit, float time = -std::numeric_limits<float>::infinity());

/// Moves secondary-ray origins off surfaces by one policy.
class RayOffset {
public:
    /// `scene_extent`: the diagonal of the scene's bounds (Scaled and Robust).
    RayOffset(OffsetPolicy policy, float scene_extent) : policy_(policy), scene_extent_(scene_extent) {}
    /// Extent taken from `scene`'s bounds.
    RayOffset(OffsetPolicy policy, const Scene& scene);

    OffsetPolicy policy() const { return policy_; }
    float scene_extent() const { return scene_extent_; }

    /// The point secondary rays leave from before the offset: robust takes
    /// accurate_hit_point, as the chapter requires (its 256 ULPs cover the
    /// error of that point, not of org + t dir); the others `surface_point`.
    Vec3f hit_point(const Scene& scene, const Rayf& ray, const Hitf& hit, const Vec3f& surface_point,
                    float time = -std::numeric_limits<float>::infinity()) const {
        return policy_ == OffsetPolicy::Robust ? accurate_hit_point(scene, ray, hit, time) : surface_point;
    }

    /// `p` moved to the side unit normal `n` points to.
    Vec3f offset(const Vec3f& p, const Vec3f& n) const;

    /// The tnear secondary rays from an offset origin start at: 0 for every
    /// policy, since the origin is already off the surface (robust: tnear = 0
    /// as the chapter prescribes; a positive tnear would skip nearby geometry).
    float tnear() const { return 0.0f; }

private:
    OffsetPolicy policy_;
    float scene_extent_;
};

/// Shadow rays toward a point light end this fraction of the way there
/// (tfar of a ray whose direction is the whole distance), so that a light
/// lying on a surface is not shadowed by that surface.
inline constexpr float kShadowRayEnd = 1.0f - 1e-6f;

/// The one way rays leave a surface (pbrt-v4's SpawnRay and SpawnRayTo):
/// `origin` is a hit point already moved off the surface by RayOffset::offset.
/// The ray is written in place: a Rayf built on the stack and copied costs
/// a store-forwarding stall per ray (measured: 4% of a gears render).
inline void spawn_ray(const Vec3f& origin, const Vec3f& dir, const RayOffset& offset, Rayf& out) {
    out.org = origin;
    out.dir = dir;
    out.tnear = offset.tnear();
    out.tfar = std::numeric_limits<float>::infinity();
}

/// A shadow ray from `origin` toward `target`, ending kShadowRayEnd of the way.
inline void spawn_ray_to(const Vec3f& origin, const Vec3f& target, const RayOffset& offset, Rayf& out) {
    spawn_ray(origin, target - origin, offset, out);
    out.tfar = kShadowRayEnd;
}

/// Waechter & Binder's offset on its own: every coordinate of `p` moved
/// 256 ULPs toward the side of `n`, or 1/65536 x extent x n where
/// |p| < extent / 32 (ULPs are too small near zero). The chapter's constants
/// are absolute (extent 1); scaling them by the scene's extent makes the
/// offset scale-invariant.
Vec3f offset_ray_origin_robust(const Vec3f& p, const Vec3f& n, float scene_extent = 1.0f);

// Inline: called for every hit and every refracted ray (an out-of-line call
// was 7% of a mount render's samples).
inline Vec3f RayOffset::offset(const Vec3f& p, const Vec3f& n) const {
    switch (policy_) {
        case OffsetPolicy::Epsilon: return p + n * 1e-4f;
        case OffsetPolicy::Scaled: {
            const float size = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
            return p + n * (1e-4f * std::max(size, 1e-3f * scene_extent_));
        }
        case OffsetPolicy::Robust: return offset_ray_origin_robust(p, n, scene_extent_);
    }
    return p;
}

}  // namespace raypack
