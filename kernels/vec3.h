#pragma once
// Small 3-vector used by the scalar reference path and the scene.
#include <algorithm>
#include <cmath>

namespace raypack {

template <class T>
struct Vec3 {
    T x{}, y{}, z{};

    constexpr Vec3() = default;
    constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    template <class U>
    constexpr explicit Vec3(const Vec3<U>& o) : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}

    constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
    constexpr Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
    constexpr Vec3& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
    // Not declared constexpr: for lane types (Vec3 of SIMD batches) the
    // comparison is not, and clang rejects the declaration then.
    friend bool operator==(const Vec3&, const Vec3&) = default;
};

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

template <class T> constexpr Vec3<T> operator+(Vec3<T> a, const Vec3<T>& b) { return a += b; }
template <class T> constexpr Vec3<T> operator-(Vec3<T> a, const Vec3<T>& b) { return a -= b; }
template <class T> constexpr Vec3<T> operator*(Vec3<T> a, T s) { return a *= s; }
template <class T> constexpr Vec3<T> operator*(T s, Vec3<T> a) { return a *= s; }
template <class T> constexpr Vec3<T> operator/(const Vec3<T>& a, T s) { return {a.x / s, a.y / s, a.z / s}; }
/// Component-wise product (colours).
template <class T> constexpr Vec3<T> operator*(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}

template <class T> constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T> constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T> T length(const Vec3<T>& a) { return std::sqrt(dot(a, a)); }
template <class T> Vec3<T> normalize(const Vec3<T>& a) { return a / length(a); }
template <class T> constexpr Vec3<T> min(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <class T> constexpr Vec3<T> max(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <class T> bool all_finite(const Vec3<T>& a) {
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

}  // namespace raypack
