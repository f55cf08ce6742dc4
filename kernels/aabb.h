#pragma once
// Axis-aligned boxes and the scalar slab test (Kay & Kajiya 1986).
#include <limits>

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

/// Slab test: does the ray meet the box within [tnear, tfar]? On success
/// `entry` is where it enters (clamped to tnear). An origin exactly on a slab
/// plane with a parallel direction gives 0 * inf = NaN; the min/max order
/// below makes a NaN drop out so that such a ray counts as inside that slab.
template <class T>
bool intersect_aabb(const Vec3<T>& org, const Vec3<T>& inv_dir, const Box3<T>& box, T tnear, T tfar,
                    T& entry) {
    T t0 = tnear, t1 = tfar;
    for (int a = 0; a < 3; ++a) {
        T ta = (box.lo[a] - org[a]) * inv_dir[a];
        T tb = (box.hi[a] - org[a]) * inv_dir[a];
        if (ta > tb) std::swap(ta, tb);
        // Written so that a NaN (0 * inf) leaves t0 / t1 unchanged.
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
    }
    entry = t0;
    return t0 <= t1;
}

}  // namespace raypack
