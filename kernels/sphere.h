#pragma once
// Scalar ray-sphere tests. Both return the nearest t in [tnear, tfar], so a
// ray starting inside the sphere hits the far side.
#include "kernels/quadratic.h"
#include "kernels/ray.h"

namespace raypack {

enum class SphereMethod { Algebraic, Geometric };

/// Textbook quadratic |o + t d - c|^2 = r^2, roots (-b -+ sqrt(b^2 - ac)) / a.
/// Loses precision when the sphere is small and far away (cancellation in
/// b^2 - ac); kept as the baseline the other methods are measured against.
template <class T>
bool intersect_sphere_algebraic(const Ray<T>& ray, const Vec3<T>& center, T radius, T& t) {
    const Vec3<T> oc = ray.org - center;
    const T a = dot(ray.dir, ray.dir);
    const T b = dot(oc, ray.dir);
    const T c = dot(oc, oc) - radius * radius;
    const T disc = b * b - a * c;
    if (!(disc >= T(0))) return false;
    const T root = std::sqrt(disc);
    return nearest_root_in((-b - root) / a, (-b + root) / a, ray.tnear, ray.tfar, t);
}

/// Geometric method (Haines, "Essential Ray Tracing Algorithms", in Glassner,
/// An Introduction to Ray Tracing, 1989): project the centre onto the ray, then
/// use the squared distance of the centre from the ray, which avoids
/// subtracting two large nearly-equal numbers.
template <class T>
bool intersect_sphere_geometric(const Ray<T>& ray, const Vec3<T>& center, T radius, T& t) {
    const Vec3<T> l = center - ray.org;
    const T a = dot(ray.dir, ray.dir);
    const T tca = dot(l, ray.dir) / a;               // closest approach along the ray
    const Vec3<T> perp = l - ray.dir * tca;          // centre minus closest point
    const T d2 = dot(perp, perp);                    // squared distance centre-ray
    const T r2 = radius * radius;
    if (!(d2 <= r2)) return false;
    const T thc = std::sqrt((r2 - d2) / a);
    return nearest_root_in(tca - thc, tca + thc, ray.tnear, ray.tfar, t);
}

template <class T>
bool intersect_sphere(SphereMethod method, const Ray<T>& ray, const Vec3<T>& center, T radius, T& t) {
    return method == SphereMethod::Algebraic ? intersect_sphere_algebraic(ray, center, radius, t)
                                             : intersect_sphere_geometric(ray, center, radius, t);
}

}  // namespace raypack
