#pragma once
// Helpers shared by the tests that check a structure against the brute-force
// oracle: readable ray and hit descriptions, random rays, shadow rays, test
// parameter names.
#include <gtest/gtest.h>

#include <algorithm>
#include <iomanip>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "accel/primitive_intersector.h"
#include "kernels/aabb.h"
#include "scene/scene.h"

namespace raypack::oracle_harness {

inline std::string describe(const Rayf& r) {
    std::ostringstream os;
    os << std::hexfloat << "org (" << r.org.x << ", " << r.org.y << ", " << r.org.z << ") dir (" << r.dir.x << ", "
       << r.dir.y << ", " << r.dir.z << ") tnear " << r.tnear << " tfar " << r.tfar << std::defaultfloat << " ["
       << r.org.x << ", " << r.org.y << ", " << r.org.z << " / " << r.dir.x << ", " << r.dir.y << ", " << r.dir.z
       << "]";
    return os.str();
}

inline std::string describe(const Hitf& h) {
    if (!h.found()) return "miss";
    std::ostringstream os;
    os << "prim " << h.prim << " t " << std::setprecision(9) << h.t;
    return os.str();
}

inline Vec3f random_direction(std::mt19937& rng) {
    std::normal_distribution<float> n;
    for (;;) {
        const Vec3f d{n(rng), n(rng), n(rng)};
        if (dot(d, d) > 1e-6f) return normalize(d);
    }
}

inline Vec3f random_point(std::mt19937& rng, const Box3f& box) {
    std::uniform_real_distribution<float> u(0, 1);
    const Vec3f e = box.extent();
    return {box.lo.x + u(rng) * e.x, box.lo.y + u(rng) * e.y, box.lo.z + u(rng) * e.z};
}

inline float signed_zero(std::mt19937& rng) { return rng() % 2 ? 0.0f : -0.0f; }

inline Box3f grown(Box3f b, float f) {
    const Vec3f e = b.extent() * f;
    b.lo -= e;
    b.hi += e;
    return b;
}

inline std::vector<Rayf> shadow_rays(const Scene& scene, const std::vector<Rayf>& rays, const std::vector<Hitf>& hits) {
    std::vector<Rayf> out;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!hits[i].found()) continue;
        const Vec3f p = rays[i].org + rays[i].dir * hits[i].t;
        for (const PointLight& light : scene.lights) {
            Rayf s;
            s.org = p;
            s.dir = light.position - p;
            s.tnear = 1e-4f;
            s.tfar = 1.0f - 1e-4f;
            out.push_back(s);
        }
    }
    return out;
}

/// A kernel may report a hit whose point lies outside the primitive's own
/// bounding box: Moeller-Trumbore for a ray in the plane y = 0 and a triangle
/// whose highest vertex is at y = -1.8e-16 (teapot), the algebraic sphere
/// test on small far spheres (cancellation, kernels/sphere.h). No bounding
/// volume structure can reproduce such hits, so a mismatch is excused (and
/// counted) when every hit the structure missed is one.
inline bool outside_own_box(const Scene& scene, const Rayf& ray, std::uint32_t prim, float t) {
    const Box3f b = primitive_bounds(scene, prim);
    for (int a = 0; a < 3; ++a) {
        const double p = double(ray.org[a]) + double(t) * double(ray.dir[a]);
        if (p < double(b.lo[a]) || p > double(b.hi[a])) return true;
    }
    return false;
}

/// True if some primitive is hit within [tnear, tfar] at a point inside its box.
inline bool hit_inside_own_box(const Scene& scene, const KernelChoice& kernels, const Rayf& ray) {
    const PrimitiveIntersector<float> isect{&scene, kernels};
    for (std::uint32_t p = 0; p < scene.primitive_count(); ++p) {
        Rayf r = ray;
        Hitf h;
        if (isect.intersect(p, r, h) && !outside_own_box(scene, ray, p, h.t)) return true;
    }
    return false;
}

inline std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string s = info.param;
    std::replace(s.begin(), s.end(), '.', '_');
    return s;
}

}  // namespace raypack::oracle_harness
