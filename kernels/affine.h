#pragma once
// 3x4 affine transforms (a linear part and a translation, row-major as NFF's
// `inst` writes them): what an instance places its object with. Rays go to
// object space with the inverse; t is unchanged because the direction is
// transformed without renormalising, so a hit's t means the same point in
// both spaces. Normals go back with the transpose of the inverse.
#include <cmath>

#include "kernels/aabb.h"
#include "kernels/vec3.h"

namespace raypack {

template <class T>
struct Affine3 {
    T m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

    Vec3<T> point(const Vec3<T>& p) const {
        return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
    }
    Vec3<T> vector(const Vec3<T>& v) const {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
    /// The transpose of the linear part applied to v: on the inverse of a
    /// transform, this carries normals the way the transform carries points.
    Vec3<T> transposed_vector(const Vec3<T>& v) const {
        return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
                m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
    }
    T determinant() const {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    }
    bool finite() const {
        for (const auto& row : m)
            for (T x : row)
                if (!std::isfinite(x)) return false;
        return true;
    }
    friend bool operator==(const Affine3&, const Affine3&) = default;
};

using Affine3f = Affine3<float>;
using Affine3d = Affine3<double>;

template <class T, class U>
Affine3<T> affine_cast(const Affine3<U>& a) {
    Affine3<T> r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = T(a.m[i][j]);
    return r;
}

/// a after b: (a * b).point(p) == a.point(b.point(p)) up to rounding.
template <class T>
Affine3<T> compose(const Affine3<T>& a, const Affine3<T>& b) {
    Affine3<T> r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 4; ++j) {
            T s = j == 3 ? a.m[i][3] : T(0);
            for (int k = 0; k < 3; ++k) s += a.m[i][k] * b.m[k][j];
            r.m[i][j] = s;
        }
    }
    return r;
}

/// The inverse (the adjugate over the determinant), or nothing useful when
/// the determinant is 0: callers reject singular transforms first.
template <class T>
Affine3<T> inverse(const Affine3<T>& a) {
    const auto& m = a.m;
    const T inv_det = T(1) / a.determinant();
    Affine3<T> r;
    r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * inv_det;
    r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv_det;
    r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv_det;
    r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * inv_det;
    r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv_det;
    r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv_det;
    r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * inv_det;
    r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv_det;
    r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv_det;
    for (int i = 0; i < 3; ++i) r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
    return r;
}

/// The box around the transformed corners of b, grown by a few ULPs so that
/// the rounding of the transform never leaves a point outside.
inline Box3f transform_box(const Affine3f& a, const Box3f& b) {
    Box3f out;
    if (b.empty()) return out;
    const Affine3d d = affine_cast<double>(a);
    Box3<double> box;
    for (int c = 0; c < 8; ++c) {
        const Vec3d p{(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z};
        box.extend(d.point(p));
    }
    const Vec3d pad = (box.hi - box.lo) * 1e-6 + Vec3d{1e-30, 1e-30, 1e-30};
    for (int k = 0; k < 3; ++k) {
        out.lo[k] = std::nextafter(float(box.lo[k] - pad[k]), -INFINITY);
        out.hi[k] = std::nextafter(float(box.hi[k] + pad[k]), INFINITY);
    }
    return out;
}

}  // namespace raypack
