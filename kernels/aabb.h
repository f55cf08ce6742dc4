#pragma once
// Axis-aligned boxes and the scalar slab test (Kay & Kajiya 1986).
#include <cmath>
#include <limits>
#include <utility>

#include "kernels/ray.h"

namespace raypack {

template <class T>
struct Box3 {
    Vec3<T> lo{std::numeric_limits<T>::infinity(), std::numeric_limits<T>::infinity(),
               std::numeric_limits<T>::infinity()};
    Vec3<T> hi{-std::numeric_limits<T>::infinity(), -std::numeric_limits<T>::infinity(),
               -std::numeric_limits<T>::infinity()};

    void extend(const Vec3<T>& p) { lo = min(lo, p); hi = max(hi, p); }
    void extend(const Box3& b) { lo = min(lo, b.lo); hi = max(hi, b.hi); }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    Vec3<T> extent() const { return hi - lo; }
    Vec3<T> center() const { return (lo + hi) * T(0.5); }
    /// Half the surface area, the quantity the SAH compares.
    T half_area() const {
        if (empty()) return T(0);
        const Vec3<T> e = extent();
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
};

using Box3f = Box3<float>;

/// Reciprocal direction for the slab test. A zero component gives +-inf with
/// the sign of the zero, so slabs the ray runs parallel to become (-inf, +inf)
/// when the origin lies strictly between the planes and empty otherwise.
template <class T>
Vec3<T> reciprocal(const Vec3<T>& d) {
    return {T(1) / d.x, T(1) / d.y, T(1) / d.z};
}

/// gamma(n) of Higham / pbrt: bound on the relative error of n roundings.
template <class T>
constexpr T rounding_gamma(int n) {
    constexpr T eps = std::numeric_limits<T>::epsilon() / 2;
    return (T(n) * eps) / (T(1) - T(n) * eps);
}

/// Slab test: does the ray meet the box within [tnear, tfar]? On success
/// `entry` is where it enters (clamped to tnear). Boundaries count as inside.
/// Conservative: each far distance is widened by 1 + 2 gamma(3) so rounding
/// never culls a box the exact ray touches, e.g. a ray aimed exactly at a
/// mesh vertex lying on the box's corner (Ize, "Robust BVH Ray Traversal",
/// JCGT 2013; pbrt-v4 Bounds3::IntersectP).
/// A direction component of +-0 means the ray runs parallel to that slab: it
/// is inside the slab for every t or for none, decided from the origin alone
/// (multiplying through the infinite reciprocal would give 0 * inf = NaN on a
/// plane, and +-inf of the wrong sign on the far plane for a -0 component).
template <class T>
bool intersect_aabb(const Vec3<T>& org, const Vec3<T>& inv_dir, const Box3<T>& box, T tnear, T tfar,
                    T& entry) {
    T t0 = tnear, t1 = tfar;
    for (int a = 0; a < 3; ++a) {
        if (std::isinf(inv_dir[a])) {
            if (org[a] < box.lo[a] || org[a] > box.hi[a]) return false;
            continue;
        }
        T ta = (box.lo[a] - org[a]) * inv_dir[a];
        T tb = (box.hi[a] - org[a]) * inv_dir[a];
        if (ta > tb) std::swap(ta, tb);
        tb *= T(1) + T(2) * rounding_gamma<T>(3);
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
    }
    entry = t0;
    return t0 <= t1;
}

}  // namespace raypack
