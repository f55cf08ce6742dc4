#pragma once
// Scalar ray-triangle tests, two-sided. (u, v) are the barycentric weights of
// vertices p1 and p2: the hit point is (1-u-v) p0 + u p1 + v p2.
#include "kernels/ray.h"

namespace raypack {

enum class TriangleMethod { Moeller, Plane };

/// Moeller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
/// JGT 1997. A zero determinant (ray parallel to the plane, or a degenerate
/// triangle) is a miss.
template <class T>
bool intersect_triangle_moeller(const Ray<T>& ray, const Vec3<T>& p0, const Vec3<T>& p1, const Vec3<T>& p2,
                                T& t, T& u, T& v) {
    const Vec3<T> e1 = p1 - p0;
    const Vec3<T> e2 = p2 - p0;
    const Vec3<T> pvec = cross(ray.dir, e2);
    const T det = dot(e1, pvec);
    if (det == T(0)) return false;
    const T inv_det = T(1) / det;
    const Vec3<T> tvec = ray.org - p0;
    const T uu = dot(tvec, pvec) * inv_det;
    if (!(uu >= T(0) && uu <= T(1))) return false;
    const Vec3<T> qvec = cross(tvec, e1);
    const T vv = dot(ray.dir, qvec) * inv_det;
    if (!(vv >= T(0) && uu + vv <= T(1))) return false;
    const T tt = dot(e2, qvec) * inv_det;
    if (!(tt >= ray.tnear && tt <= ray.tfar)) return false;
    t = tt;
    u = uu;
    v = vv;
    return true;
}

/// Plane intersection followed by an inside test with edge functions
/// (the classical approach, e.g. Glassner 1989, ch. 2): t from the plane
/// equation, then the hit point's barycentrics from sub-triangle areas.
template <class T>
bool intersect_triangle_plane(const Ray<T>& ray, const Vec3<T>& p0, const Vec3<T>& p1, const Vec3<T>& p2,
                              T& t, T& u, T& v) {
    const Vec3<T> e1 = p1 - p0;
    const Vec3<T> e2 = p2 - p0;
    const Vec3<T> n = cross(e1, e2);
    const T denom = dot(n, ray.dir);
    if (denom == T(0)) return false;
    const T tt = dot(n, p0 - ray.org) / denom;
    if (!(tt >= ray.tnear && tt <= ray.tfar)) return false;
    const Vec3<T> q = ray.org + ray.dir * tt - p0;
    const T nn = dot(n, n);
    const T uu = dot(n, cross(q, e2)) / nn;
    const T vv = dot(n, cross(e1, q)) / nn;
    if (!(uu >= T(0) && vv >= T(0) && uu + vv <= T(1))) return false;
    t = tt;
    u = uu;
    v = vv;
    return true;
}

template <class T>
bool intersect_triangle(TriangleMethod method, const Ray<T>& ray, const Vec3<T>& p0, const Vec3<T>& p1,
                        const Vec3<T>& p2, T& t, T& u, T& v) {
    return method == TriangleMethod::Moeller ? intersect_triangle_moeller(ray, p0, p1, p2, t, u, v)
                                             : intersect_triangle_plane(ray, p0, p1, p2, t, u, v);
}

}  // namespace raypack
