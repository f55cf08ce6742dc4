#pragma once
// Ray-sphere tests, written once for every lane type (kernels/simd.h): K rays
// against one sphere (sphere fields broadcast) or one ray against K spheres
// stored as SoA (ray fields broadcast). Every variant returns the lanes of
// `valid` that hit, with the nearest root in [tnear, tfar] in `t`, so a ray
// starting inside the sphere hits the far side. `t` is meaningful on the
// returned lanes only. dir need not be unit length. Each variant takes the ray
// as a QuadricRay (|dir|^2 and its reciprocal precomputed once per ray) or as
// its fields. A sphere whose squared radius is zero (r = 0, or r < ~1e-19 in
// float) is a point and never hit, as degenerate triangles are not: otherwise
// a ray passing it at 1e-30 would hit it by underflow, outside its box.
#include "kernels/quadratic.h"
#include "kernels/ray.h"

namespace raypack {

enum class SphereMethod { Algebraic, Geometric, Precise };

/// Textbook quadratic |o + t d - c|^2 = r^2, roots (-b -+ sqrt(b^2 - ac)) / a
/// (half linear coefficient b). Loses precision when the sphere is small and
/// far away (cancellation in b^2 - ac); kept as the baseline the other
/// methods are measured against.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_sphere_algebraic(mask_of<F> valid, const QuadricRay<F>& ray,
                                                         const Vec3<F>& center, const F& radius, F& t) {
    const Vec3<F> oc = (ray.org - center);
    const F b = fused_dot(oc, ray.dir);
    const F r2 = radius * radius;
    const F c = fused_dot(oc, oc) - r2;
    const F disc = vfmsub(b, b, ray.dd * c);
    valid = valid & (disc >= F(0)) & (r2 > F(0));
    if (none(valid)) return valid;
    const F root = vsqrt(disc);
    const F nb = -b;
    return nearest_root(valid, (nb - root) * ray.inv_dd, (nb + root) * ray.inv_dd, ray.tnear, ray.tfar, t);
}

/// Geometric method (Haines, "Essential Ray Tracing Algorithms", in Glassner,
/// An Introduction to Ray Tracing, 1989): project the centre onto the ray, then
/// use the squared distance of the centre from the ray, which avoids
/// subtracting two large nearly-equal numbers.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_sphere_geometric(mask_of<F> valid, const QuadricRay<F>& ray,
                                                         const Vec3<F>& center, const F& radius, F& t) {
    const Vec3<F> l = (center - ray.org);
    const F tca = fused_dot(l, ray.dir) * ray.inv_dd;        // closest approach along the ray
    const Vec3<F> perp = fused_sub_scaled(l, ray.dir, tca);  // centre minus closest point
    const F d2 = fused_dot(perp, perp);                      // squared distance centre-ray
    const F r2 = radius * radius;
    valid = valid & (d2 <= r2) & (r2 > F(0));
    if (none(valid)) return valid;
    const F thc = vsqrt((r2 - d2) * ray.inv_dd);
    return nearest_root(valid, tca - thc, tca + thc, ray.tnear, ray.tfar, t);
}

/// Haines, Guenther, Akenine-Moeller, "Precision Improvements for Ray/Sphere
/// Intersection", Ray Tracing Gems ch. 7 (2019): with f = o - c and
/// b = f . d, the discriminant b^2 - ac is a (r^2 - |f - (b/a) d|^2), from
/// the squared distance of the centre to the ray (no cancellation of large
/// terms), and the roots are the stable pair q / a, c / q with
/// q = -(b + sign(b) sqrt(b^2 - ac)) (Press et al., Numerical Recipes 5.6).
template <class F>
RAYPACK_INLINE mask_of<F> intersect_sphere_precise(mask_of<F> valid, const QuadricRay<F>& ray,
                                                       const Vec3<F>& center, const F& radius, F& t) {
    const Vec3<F> f = (ray.org - center);
    const F b = fused_dot(f, ray.dir);
    const Vec3<F> l = fused_sub_scaled(f, ray.dir, b * ray.inv_dd);  // f minus its projection on the ray
    const F r2 = radius * radius;
    const F h2 = r2 - fused_dot(l, l);  // discriminant / a
    valid = valid & (h2 >= F(0)) & (r2 > F(0));
    if (none(valid)) return valid;
    // c with the same r2 as h2: then h2 == 0 with b == 0 (a tangent ray from
    // the surface) gives c == 0 and the 0 / 0 below is dropped by vmin/vmax.
    const F c = fused_dot(f, f) - r2;
    const F q = -(b + copysign_of(vsqrt(ray.dd * h2), b));
    const F t_q = q * ray.inv_dd, t_c = c / q;
    // vmin/vmax return the second operand when the first is NaN (q == 0).
    return nearest_root(valid, vmin(t_c, t_q), vmax(t_c, t_q), ray.tnear, ray.tfar, t);
}

/// The variant chosen at compile time.
template <SphereMethod Method, class F>
RAYPACK_INLINE mask_of<F> intersect_sphere(mask_of<F> valid, const QuadricRay<F>& ray, const Vec3<F>& center,
                                               const F& radius, F& t) {
    if constexpr (Method == SphereMethod::Algebraic)
        return intersect_sphere_algebraic<F>(valid, ray, center, radius, t);
    else if constexpr (Method == SphereMethod::Geometric)
        return intersect_sphere_geometric<F>(valid, ray, center, radius, t);
    else
        return intersect_sphere_precise<F>(valid, ray, center, radius, t);
}

/// The same from the ray's fields (computes |dir|^2 and its reciprocal).
template <SphereMethod Method, class F>
RAYPACK_INLINE mask_of<F> intersect_sphere(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                               const F& tnear, const F& tfar, const Vec3<F>& center, const F& radius,
                                               F& t) {
    return intersect_sphere<Method, F>(valid, make_quadric_ray<F>(org, dir, tnear, tfar), center, radius, t);
}
template <class F>
RAYPACK_INLINE mask_of<F> intersect_sphere_algebraic(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                         const F& tnear, const F& tfar, const Vec3<F>& center,
                                                         const F& radius, F& t) {
    return intersect_sphere<SphereMethod::Algebraic, F>(valid, org, dir, tnear, tfar, center, radius, t);
}
template <class F>
RAYPACK_INLINE mask_of<F> intersect_sphere_geometric(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                         const F& tnear, const F& tfar, const Vec3<F>& center,
                                                         const F& radius, F& t) {
    return intersect_sphere<SphereMethod::Geometric, F>(valid, org, dir, tnear, tfar, center, radius, t);
}
template <class F>
RAYPACK_INLINE mask_of<F> intersect_sphere_precise(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                       const F& tnear, const F& tfar, const Vec3<F>& center,
                                                       const F& radius, F& t) {
    return intersect_sphere<SphereMethod::Precise, F>(valid, org, dir, tnear, tfar, center, radius, t);
}

// ---- Scalar entry points: one ray, one sphere; `t` untouched on a miss -----

template <SphereMethod Method, class T>
bool intersect_sphere(const Ray<T>& ray, const Vec3<T>& center, T radius, T& t) {
    T tt;
    if (!intersect_sphere<Method, T>(true, ray.org, ray.dir, ray.tnear, ray.tfar, center, radius, tt)) return false;
    t = tt;
    return true;
}

template <class T>
bool intersect_sphere_algebraic(const Ray<T>& ray, const Vec3<T>& center, T radius, T& t) {
    return intersect_sphere<SphereMethod::Algebraic>(ray, center, radius, t);
}

template <class T>
bool intersect_sphere_geometric(const Ray<T>& ray, const Vec3<T>& center, T radius, T& t) {
    return intersect_sphere<SphereMethod::Geometric>(ray, center, radius, t);
}

template <class T>
bool intersect_sphere_precise(const Ray<T>& ray, const Vec3<T>& center, T radius, T& t) {
    return intersect_sphere<SphereMethod::Precise>(ray, center, radius, t);
}

template <class T>
bool intersect_sphere(SphereMethod method, const Ray<T>& ray, const Vec3<T>& center, T radius, T& t) {
    switch (method) {
        case SphereMethod::Algebraic: return intersect_sphere<SphereMethod::Algebraic>(ray, center, radius, t);
        case SphereMethod::Geometric: return intersect_sphere<SphereMethod::Geometric>(ray, center, radius, t);
        case SphereMethod::Precise: break;
    }
    return intersect_sphere<SphereMethod::Precise>(ray, center, radius, t);
}

}  // namespace raypack
