#pragma once
// Vector and matrix helpers for the SPD generators (Haines 1987, "A Proposal
// for Standard Graphics Environments"). The reference NFF files are printed
// with %g, so every result must round like the SPD library's double
// arithmetic: each helper evaluates its terms in the SPD library's order
// (row vectors times row-major matrices, sums left to right, explicit
// "+ w * m[3][j]" terms that turn -0 into +0). Don't "simplify" them.
#include <array>
#include <cmath>

namespace raypack::spd {

/// The SPD library's value of pi (def.h), which is M_PI to the last bit.
inline constexpr double kPi = 3.141592653589793;

struct Vec3 {
    double x = 0, y = 0, z = 0;
};

/// A point with a fourth component: a radius for spheres and cone ends, a
/// homogeneous coordinate for matrix products.
struct Vec4 {
    double x = 0, y = 0, z = 0, w = 0;
    Vec3 xyz() const { return {x, y, z}; }
};

/// Row-major 4x4; points are row vectors multiplied from the left.
using Mat4 = std::array<std::array<double, 4>, 4>;

enum class Axis { X, Y, Z };

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

inline Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/// Divides V by its length unless the length is zero; returns the length.
inline double normalize(Vec3& v) {
    const double len = std::sqrt(dot(v, v));
    if (len > 0.0) {
        v.x /= len;
        v.y /= len;
        v.z /= len;
    }
    return len;
}

inline Mat4 zero_matrix() { return Mat4{}; }

inline Mat4 identity_matrix() {
    Mat4 m = zero_matrix();
    for (int i = 0; i < 4; ++i) m[i][i] = 1.0;
    return m;
}

/// Rotation by ANGLE radians about a coordinate axis.
inline Mat4 rotate_matrix(Axis axis, double angle) {
    Mat4 m = zero_matrix();
    const double c = std::cos(angle);
    const double s = std::sin(angle);
    switch (axis) {
    case Axis::X:
        m[0][0] = 1.0;
        m[1][1] = c;
        m[2][2] = c;
        m[1][2] = s;
        m[2][1] = -s;
        break;
    case Axis::Y:
        m[1][1] = 1.0;
        m[0][0] = c;
        m[2][2] = c;
        m[2][0] = s;
        m[0][2] = -s;
        break;
    case Axis::Z:
        m[2][2] = 1.0;
        m[0][0] = c;
        m[1][1] = c;
        m[0][1] = s;
        m[1][0] = -s;
        break;
    }
    m[3][3] = 1.0;
    return m;
}

/// Rotation by ANGLE radians about the unit vector A.
inline Mat4 axis_rotate_matrix(const Vec3& a, double angle) {
    const double c = std::cos(angle);
    const double s = std::sin(angle);
    const double t = 1.0 - c;
    Mat4 m{};
    m[0][0] = a.x * a.x + (1.0 - a.x * a.x) * c;
    m[0][1] = a.x * a.y * t + a.z * s;
    m[0][2] = a.x * a.z * t - a.y * s;
    m[1][0] = a.x * a.y * t - a.z * s;
    m[1][1] = a.y * a.y + (1.0 - a.y * a.y) * c;
    m[1][2] = a.y * a.z * t + a.x * s;
    m[2][0] = a.x * a.z * t + a.y * s;
    m[2][1] = a.y * a.z * t - a.x * s;
    m[2][2] = a.z * a.z + (1.0 - a.z * a.z) * c;
    m[3][3] = 1.0;
    return m;
}

inline Mat4 translate_matrix(const Vec3& v) {
    Mat4 m = identity_matrix();
    m[3][0] = v.x;
    m[3][1] = v.y;
    m[3][2] = v.z;
    return m;
}

inline Mat4 scale_matrix(const Vec3& v) {
    Mat4 m = zero_matrix();
    m[0][0] = v.x;
    m[1][1] = v.y;
    m[2][2] = v.z;
    m[3][3] = 1.0;
    return m;
}

inline Mat4 multiply(const Mat4& a, const Mat4& b) {
    Mat4 r{};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j];
    return r;
}

/// Direction times the upper 3x3 (no translation).
inline Vec3 transform_vector(const Vec3& v, const Mat4& m) {
    return {v.x * m[0][0] + v.y * m[1][0] + v.z * m[2][0],
            v.x * m[0][1] + v.y * m[1][1] + v.z * m[2][1],
            v.x * m[0][2] + v.y * m[1][2] + v.z * m[2][2]};
}

/// Normal times the transposed upper 3x3.
inline Vec3 transform_normal(const Vec3& v, const Mat4& m) {
    return {v.x * m[0][0] + v.y * m[0][1] + v.z * m[0][2],
            v.x * m[1][0] + v.y * m[1][1] + v.z * m[1][2],
            v.x * m[2][0] + v.y * m[2][1] + v.z * m[2][2]};
}

/// Point (implicit w = 1) times the matrix, without the perspective column.
inline Vec3 transform_point(const Vec3& v, const Mat4& m) {
    return {v.x * m[0][0] + v.y * m[1][0] + v.z * m[2][0] + m[3][0],
            v.x * m[0][1] + v.y * m[1][1] + v.z * m[2][1] + m[3][1],
            v.x * m[0][2] + v.y * m[1][2] + v.z * m[2][2] + m[3][2]};
}

/// Full homogeneous product; the w term is added even when it is zero.
inline Vec4 transform_coord(const Vec4& v, const Mat4& m) {
    return {v.x * m[0][0] + v.y * m[1][0] + v.z * m[2][0] + v.w * m[3][0],
            v.x * m[0][1] + v.y * m[1][1] + v.z * m[2][1] + v.w * m[3][1],
            v.x * m[0][2] + v.y * m[1][2] + v.z * m[2][2] + v.w * m[3][2],
            v.x * m[0][3] + v.y * m[1][3] + v.z * m[2][3] + v.w * m[3][3]};
}

}  // namespace raypack::spd
