#pragma once
// Rays and hits of the scalar reference path (width 1).
#include <cstdint>
#include <limits>

#include "kernels/vec3.h"

namespace raypack {

inline constexpr std::uint32_t kNoPrim = 0xFFFFFFFFu;

/// A ray segment: points org + t * dir for tnear <= t <= tfar. dir need not be unit length.
template <class T>
struct Ray {
    Vec3<T> org;
    Vec3<T> dir;
    T tnear = T(0);
    T tfar = std::numeric_limits<T>::infinity();
};

/// Closest hit: t along the ray, the scene-global primitive number, and the
/// primitive's own parameters (barycentrics for triangles, see each kernel).
template <class T>
struct Hit {
    T t = std::numeric_limits<T>::infinity();
    std::uint32_t prim = kNoPrim;
    T u = T(0);
    T v = T(0);
    bool found() const { return prim != kNoPrim; }
};

using Rayf = Ray<float>;
using Hitf = Hit<float>;

}  // namespace raypack
