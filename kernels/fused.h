#pragma once
// Vector products with fused multiply-adds, for every lane type: fewer
// instructions than separate products and sums, and the same operations at
// every width, so width 1 and width K agree bit for bit.
#include "kernels/simd.h"
#include "kernels/vec3.h"

namespace raypack {

/// keep_in_register (simd.h) for each component.
template <class F>
RAYPACK_INLINE void keep_in_register(Vec3<F>& v) {
    keep_in_register(v.x), keep_in_register(v.y), keep_in_register(v.z);
}

/// a . b as one product and two fused multiply-adds.
template <class F>
RAYPACK_INLINE F fused_dot(const Vec3<F>& a, const Vec3<F>& b) {
    return vfmadd(a.x, b.x, vfmadd(a.y, b.y, a.z * b.z));
}

/// a x b, each component one product and one fused multiply-subtract.
template <class F>
RAYPACK_INLINE Vec3<F> fused_cross(const Vec3<F>& a, const Vec3<F>& b) {
    return {vfmsub(a.y, b.z, a.z * b.y), vfmsub(a.z, b.x, a.x * b.z), vfmsub(a.x, b.y, a.y * b.x)};
}

/// a - b * s per component, fused.
template <class F>
RAYPACK_INLINE Vec3<F> fused_sub_scaled(const Vec3<F>& a, const Vec3<F>& b, const F& s) {
    return {vfnmadd(b.x, s, a.x), vfnmadd(b.y, s, a.y), vfnmadd(b.z, s, a.z)};
}

}  // namespace raypack
