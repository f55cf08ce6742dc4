#include "render/ray_offset.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace raypack {
namespace {

constexpr OffsetPolicy kPolicies[] = {OffsetPolicy::Epsilon, OffsetPolicy::Scaled, OffsetPolicy::Robust};

// Waechter & Binder, "A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems (2019), ch. 6, listing 6-1. The
// published origin threshold and float offset are absolute, i.e. tuned for a
// scene of size about 1: in a scene of size 1e-4 the 1/65536 offset jumps over
// whole objects (issue 19). Here both are in units of the scene's extent, so
// the method reads the same at any scale; the ULP part is relative already.
constexpr float kOrigin = 1.0f / 32.0f;        // x extent: below this magnitude, offset in absolute terms
constexpr float kFloatScale = 1.0f / 65536.0f;  // x extent: the absolute offset there
constexpr float kIntScale = 256.0f;             // ULPs elsewhere

/// `x` moved by `ulps` units in the last place, away from zero when ulps > 0
/// and x > 0 (adding to the integer image of a float walks its magnitude).
float add_ulps(float x, int ulps) {
    const auto bits = std::bit_cast<std::int32_t>(x);
    return std::bit_cast<float>(bits + (x < 0 ? -ulps : ulps));
}

float offset_coordinate(float p, float n, float extent) {
    if (std::fabs(p) < kOrigin * extent) return p + kFloatScale * extent * n;
    return add_ulps(p, int(kIntScale * n));
}

}  // namespace

const char* offset_policy_name(OffsetPolicy policy) {
    switch (policy) {
        case OffsetPolicy::Epsilon: return "epsilon";
        case OffsetPolicy::Scaled: return "scaled";
        case OffsetPolicy::Robust: return "robust";
    }
    return "?";
}

std::optional<OffsetPolicy> parse_offset_policy(const std::string& name) {
    for (OffsetPolicy p : kPolicies)
        if (name == offset_policy_name(p)) return p;
    return std::nullopt;
}

std::string offset_policy_list() {
    std::string out;
    for (OffsetPolicy p : kPolicies) {
        if (!out.empty()) out += '|';
        out += offset_policy_name(p);
    }
    return out;
}

Vec3f offset_ray_origin_robust(const Vec3f& p, const Vec3f& n, float scene_extent) {
    return {offset_coordinate(p.x, n.x, scene_extent), offset_coordinate(p.y, n.y, scene_extent),
            offset_coordinate(p.z, n.z, scene_extent)};
}

namespace {

/// accurate_hit_point in scene `scene` (the top scene or an object) of the
/// top scene `top`.
Vec3f point_in(const Scene& top, const Scene& scene, const Rayf& ray, const Hitf& hit, float time) {
    if (hit.prim >= scene.prims.size()) {
        // Inside an instance: the point in object space, placed.
        const HitInPlacement in = hit_in_placement(scene, ray, hit, time);
        return in.to_world.point(point_in(top, *top.objects[in.instance->object], in.ray, in.hit, time));
    }
    const PrimRef ref = scene.prims[hit.prim];
    const std::uint32_t i = ref.index;
    switch (ref.kind) {
        case PrimKind::Triangle: {
            const TriangleSoA& t = scene.triangles;
            // From p0 along the edges: the small products carry small errors
            // and only the last sum rounds at the magnitude of the point.
            return t.p0[i] + ((t.p1[i] - t.p0[i]) * hit.u + (t.p2[i] - t.p0[i]) * hit.v);
        }
        case PrimKind::Sphere: {
            const Vec3f c = scene.spheres.center[i];
            const Vec3f d = ray.org + ray.dir * hit.t - c;
            const float len = length(d);
            return len > 0 ? c + d * (scene.spheres.radius[i] / len) : c + d;
        }
        case PrimKind::HeightField: return height_field_point(scene.height_fields[i], hit.u, hit.v);
        case PrimKind::Cone:
        case PrimKind::Instance: break;
    }
    return ray.org + ray.dir * hit.t;
}

}  // namespace

Vec3f accurate_hit_point(const Scene& scene, const Rayf& ray, const Hitf& hit, float time) {
    return point_in(scene, scene, ray, hit, time);
}

RayOffset::RayOffset(OffsetPolicy policy, const Scene& scene) : policy_(policy), scene_extent_(1.0f) {
    const Box3f b = scene_bounds(scene);
    scene_extent_ = b.empty() ? 1.0f : std::max(length(b.extent()), 1e-30f);
}

}  // namespace raypack
