// Analytic answers for the scalar kernels, in float and in double. Rays and
// shapes are chosen so that the exact answer is representable and the
// operations the kernels perform on them are exact; where rounding cannot be
// avoided the tolerance is a few units in the last place.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "kernels/aabb.h"
#include "kernels/cone.h"
#include "kernels/quadratic.h"
#include "kernels/sphere.h"
#include "kernels/triangle.h"

namespace raypack {
namespace {

// Every test runs in float and in double. (A TYPED_TEST would be named
// Kernels/0.Name, which the filter 'Kernels.*' does not select.)
#define KERNEL_TEST(Name)                      \
    template <class T>                         \
    void Name##_body();                        \
    TEST(Kernels, Name) {                      \
        {                                      \
            SCOPED_TRACE("float");             \
            Name##_body<float>();              \
        }                                      \
        {                                      \
            SCOPED_TRACE("double");            \
            Name##_body<double>();             \
        }                                      \
    }                                          \
    template <class T>                         \
    void Name##_body()

template <class T>
constexpr T kEps = std::numeric_limits<T>::epsilon();
template <class T>
constexpr T kInf = std::numeric_limits<T>::infinity();

template <class T>
Ray<T> make_ray(Vec3<T> org, Vec3<T> dir, T tnear = T(0), T tfar = kInf<T>) {
    Ray<T> r;
    r.org = org;
    r.dir = dir;
    r.tnear = tnear;
    r.tfar = tfar;
    return r;
}

constexpr SphereMethod kSphereMethods[] = {SphereMethod::Algebraic, SphereMethod::Geometric};
constexpr TriangleMethod kTriangleMethods[] = {TriangleMethod::Moeller, TriangleMethod::Plane};

const char* name(SphereMethod m) { return m == SphereMethod::Algebraic ? "algebraic" : "geometric"; }
const char* name(TriangleMethod m) { return m == TriangleMethod::Moeller ? "moeller" : "plane"; }

// ---- Spheres: centre 0, radius 2 -----------------------------------------

KERNEL_TEST(SphereHitFromOutsideExact) {
    for (SphereMethod m : kSphereMethods) {
        SCOPED_TRACE(name(m));
        for (int axis = 0; axis < 3; ++axis) {
            for (T sign : {T(1), T(-1)}) {
                Vec3<T> org{}, dir{};
                org[axis] = -sign * T(5);
                dir[axis] = sign;
                T t = -1;
                ASSERT_TRUE(intersect_sphere(m, make_ray(org, dir), Vec3<T>{}, T(2), t));
                EXPECT_EQ(t, T(3));
            }
        }
        // Off-centre axis ray: |(1.5, 0, z)| = 2 at z = -sqrt(1.75).
        T t = -1;
        ASSERT_TRUE(intersect_sphere(m, make_ray(Vec3<T>{1.5, 0, -5}, Vec3<T>{0, 0, 1}), Vec3<T>{}, T(2), t));
        const long double expect = 5.0L - std::sqrt(1.75L);
        EXPECT_NEAR(double(t), double(expect), 4 * double(kEps<T>) * 5);
    }
}

KERNEL_TEST(SphereRayStartingInsideHitsFarSide) {
    for (SphereMethod m : kSphereMethods) {
        SCOPED_TRACE(name(m));
        T t = -1;
        ASSERT_TRUE(intersect_sphere(m, make_ray(Vec3<T>{0, 0, 1}, Vec3<T>{0, 0, 1}), Vec3<T>{}, T(2), t));
        EXPECT_EQ(t, T(1));
        ASSERT_TRUE(intersect_sphere(m, make_ray(Vec3<T>{0, 0, 0}, Vec3<T>{-1, 0, 0}), Vec3<T>{}, T(2), t));
        EXPECT_EQ(t, T(2));
    }
}

KERNEL_TEST(SphereBehindRayMisses) {
    for (SphereMethod m : kSphereMethods) {
        SCOPED_TRACE(name(m));
        T t = -1;
        EXPECT_FALSE(intersect_sphere(m, make_ray(Vec3<T>{0, 0, 5}, Vec3<T>{0, 0, 1}), Vec3<T>{}, T(2), t));
        EXPECT_FALSE(intersect_sphere(m, make_ray(Vec3<T>{5, 5, 5}, Vec3<T>{1, 1, 1}), Vec3<T>{}, T(2), t));
        EXPECT_EQ(t, T(-1));  // untouched on a miss
    }
}

KERNEL_TEST(SphereTangentHitsGrazingMisses) {
    for (SphereMethod m : kSphereMethods) {
        SCOPED_TRACE(name(m));
        T t = -1;
        // x = 2 exactly: the discriminant is exactly 0, one hit at z = 0.
        ASSERT_TRUE(intersect_sphere(m, make_ray(Vec3<T>{2, 0, -5}, Vec3<T>{0, 0, 1}), Vec3<T>{}, T(2), t));
        EXPECT_NEAR(double(t), 5.0, 8 * double(kEps<T>) * 5);
        // A few ulps outside: the squared distance 4 (1 + 16 eps) exceeds r^2
        // by more than the rounding of either method.
        const T x = T(2) * (T(1) + T(8) * kEps<T>);
        EXPECT_FALSE(intersect_sphere(m, make_ray(Vec3<T>{x, 0, -5}, Vec3<T>{0, 0, 1}), Vec3<T>{}, T(2), t));
        EXPECT_FALSE(intersect_sphere(m, make_ray(Vec3<T>{0, -x, -5}, Vec3<T>{0, 0, 1}), Vec3<T>{}, T(2), t));
        // And a few ulps inside hits.
        const T xi = T(2) * (T(1) - T(8) * kEps<T>);
        EXPECT_TRUE(intersect_sphere(m, make_ray(Vec3<T>{xi, 0, -5}, Vec3<T>{0, 0, 1}), Vec3<T>{}, T(2), t));
    }
}

KERNEL_TEST(SphereUnnormalizedDirectionGivesTInDirectionUnits) {
    for (SphereMethod m : kSphereMethods) {
        SCOPED_TRACE(name(m));
        T t = -1;
        ASSERT_TRUE(intersect_sphere(m, make_ray(Vec3<T>{0, 0, -5}, Vec3<T>{0, 0, 2}), Vec3<T>{}, T(2), t));
        EXPECT_EQ(t, T(1.5));
        ASSERT_TRUE(intersect_sphere(m, make_ray(Vec3<T>{0, -5, 0}, Vec3<T>{0, 0.25, 0}), Vec3<T>{}, T(2), t));
        EXPECT_EQ(t, T(12));
        // Diagonal direction (3, 4, 0) of length 5, from 10 units away: t = (10 - 2) / 5.
        ASSERT_TRUE(intersect_sphere(m, make_ray(Vec3<T>{-6, -8, 0}, Vec3<T>{3, 4, 0}), Vec3<T>{}, T(2), t));
        EXPECT_NEAR(double(t), 1.6, 4 * double(kEps<T>) * 1.6);
    }
}

KERNEL_TEST(SphereTnearTfarClipping) {
    const Vec3<T> org{0, 0, -5}, dir{0, 0, 1};
    for (SphereMethod m : kSphereMethods) {
        SCOPED_TRACE(name(m));
        T t = -1;
        ASSERT_TRUE(intersect_sphere(m, make_ray(org, dir, T(4)), Vec3<T>{}, T(2), t));
        EXPECT_EQ(t, T(7));  // near root 3 clipped away: far root
        ASSERT_TRUE(intersect_sphere(m, make_ray(org, dir, T(3)), Vec3<T>{}, T(2), t));
        EXPECT_EQ(t, T(3));  // tnear is inclusive
        ASSERT_TRUE(intersect_sphere(m, make_ray(org, dir, T(0), T(3)), Vec3<T>{}, T(2), t));
        EXPECT_EQ(t, T(3));  // so is tfar
        EXPECT_FALSE(intersect_sphere(m, make_ray(org, dir, T(7.5)), Vec3<T>{}, T(2), t));
        EXPECT_FALSE(intersect_sphere(m, make_ray(org, dir, T(0), T(2.5)), Vec3<T>{}, T(2), t));
        EXPECT_FALSE(intersect_sphere(m, make_ray(org, dir, T(3.5), T(6.5)), Vec3<T>{}, T(2), t));
    }
}

// ---- Triangles: (0,0,0), (1,0,0), (0,1,0) in the plane z = 0 --------------

template <class T>
struct UnitTriangle {
    Vec3<T> p0{0, 0, 0}, p1{1, 0, 0}, p2{0, 1, 0};
};

KERNEL_TEST(TriangleHitExactBarycentrics) {
    const UnitTriangle<T> tri;
    for (TriangleMethod m : kTriangleMethods) {
        SCOPED_TRACE(name(m));
        T t = -1, u = -1, v = -1;
        ASSERT_TRUE(intersect_triangle(m, make_ray(Vec3<T>{0.25, 0.5, -2}, Vec3<T>{0, 0, 1}), tri.p0, tri.p1, tri.p2,
                                       t, u, v));
        EXPECT_EQ(t, T(2));
        EXPECT_EQ(u, T(0.25));
        EXPECT_EQ(v, T(0.5));
    }
}

KERNEL_TEST(TriangleCentroidHit) {
    const Vec3<T> p0{0, 0, 0}, p1{3, 0, 0}, p2{0, 3, 0};
    for (TriangleMethod m : kTriangleMethods) {
        SCOPED_TRACE(name(m));
        T t = -1, u = -1, v = -1;
        ASSERT_TRUE(intersect_triangle(m, make_ray(Vec3<T>{1, 1, 4}, Vec3<T>{0, 0, -2}), p0, p1, p2, t, u, v));
        EXPECT_NEAR(double(t), 2.0, 4 * double(kEps<T>));
        EXPECT_NEAR(double(u), 1.0 / 3.0, 2 * double(kEps<T>));
        EXPECT_NEAR(double(v), 1.0 / 3.0, 2 * double(kEps<T>));
    }
}

KERNEL_TEST(TriangleEdgesAndVerticesHit) {
    const UnitTriangle<T> tri;
    // (point, expected u, expected v): the three vertices and a point on each edge.
    const T cases[][4] = {{0, 0, 0, 0},     {1, 0, 1, 0},     {0, 1, 0, 1},
                          {0.5, 0, 0.5, 0}, {0, 0.5, 0, 0.5}, {0.5, 0.5, 0.5, 0.5}};
    for (TriangleMethod m : kTriangleMethods) {
        SCOPED_TRACE(name(m));
        for (const auto& c : cases) {
            SCOPED_TRACE(::testing::Message() << "point " << c[0] << " " << c[1]);
            T t = -1, u = -1, v = -1;
            ASSERT_TRUE(intersect_triangle(m, make_ray(Vec3<T>{c[0], c[1], -1}, Vec3<T>{0, 0, 1}), tri.p0, tri.p1,
                                           tri.p2, t, u, v));
            EXPECT_EQ(t, T(1));
            EXPECT_EQ(u, c[2]);
            EXPECT_EQ(v, c[3]);
        }
    }
}

KERNEL_TEST(TriangleJustOutsideMisses) {
    const UnitTriangle<T> tri;
    const T d = T(4) * kEps<T>;  // representable steps past each edge
    const Vec3<T> outside[] = {{T(0.5) + d, T(0.5), -1}, {-d, T(0.25), -1}, {T(0.25), -d, -1}, {T(1) + 2 * d, 0, -1}};
    for (TriangleMethod m : kTriangleMethods) {
        SCOPED_TRACE(name(m));
        for (const Vec3<T>& o : outside) {
            T t = -1, u = -1, v = -1;
            EXPECT_FALSE(intersect_triangle(m, make_ray(o, Vec3<T>{0, 0, 1}), tri.p0, tri.p1, tri.p2, t, u, v))
                << o.x << " " << o.y;
        }
    }
}

KERNEL_TEST(TriangleParallelRayMisses) {
    const UnitTriangle<T> tri;
    for (TriangleMethod m : kTriangleMethods) {
        SCOPED_TRACE(name(m));
        T t = -1, u = -1, v = -1;
        // Above the plane, and inside the plane through the triangle.
        EXPECT_FALSE(intersect_triangle(m, make_ray(Vec3<T>{-1, 0.25, 1}, Vec3<T>{1, 0, 0}), tri.p0, tri.p1, tri.p2,
                                        t, u, v));
        EXPECT_FALSE(intersect_triangle(m, make_ray(Vec3<T>{-1, 0.25, 0}, Vec3<T>{1, 0, 0}), tri.p0, tri.p1, tri.p2,
                                        t, u, v));
    }
}

KERNEL_TEST(TriangleBackSideHits) {
    const UnitTriangle<T> tri;  // normal +z
    for (TriangleMethod m : kTriangleMethods) {
        SCOPED_TRACE(name(m));
        T t = -1, u = -1, v = -1;
        ASSERT_TRUE(intersect_triangle(m, make_ray(Vec3<T>{0.25, 0.5, 2}, Vec3<T>{0, 0, -1}), tri.p0, tri.p1, tri.p2,
                                       t, u, v));
        EXPECT_EQ(t, T(2));
        EXPECT_EQ(u, T(0.25));
        EXPECT_EQ(v, T(0.5));
    }
}

KERNEL_TEST(DegenerateTriangleMisses) {
    for (TriangleMethod m : kTriangleMethods) {
        SCOPED_TRACE(name(m));
        T t = -1, u = -1, v = -1;
        // Collinear vertices: the ray passes through the segment they span.
        EXPECT_FALSE(intersect_triangle(m, make_ray(Vec3<T>{0.5, 0.5, -1}, Vec3<T>{0, 0, 1}), Vec3<T>{0, 0, 0},
                                        Vec3<T>{1, 1, 0}, Vec3<T>{2, 2, 0}, t, u, v));
        // All three vertices equal, on the ray.
        EXPECT_FALSE(intersect_triangle(m, make_ray(Vec3<T>{0.5, 0.5, -1}, Vec3<T>{0, 0, 1}), Vec3<T>{0.5, 0.5, 0},
                                        Vec3<T>{0.5, 0.5, 0}, Vec3<T>{0.5, 0.5, 0}, t, u, v));
    }
}

KERNEL_TEST(TriangleBehindOriginMisses) {
    const UnitTriangle<T> tri;
    for (TriangleMethod m : kTriangleMethods) {
        SCOPED_TRACE(name(m));
        T t = -1, u = -1, v = -1;
        EXPECT_FALSE(intersect_triangle(m, make_ray(Vec3<T>{0.25, 0.5, 1}, Vec3<T>{0, 0, 1}), tri.p0, tri.p1, tri.p2,
                                        t, u, v));
        // ... but is found once the interval reaches back to it.
        ASSERT_TRUE(intersect_triangle(m, make_ray(Vec3<T>{0.25, 0.5, 1}, Vec3<T>{0, 0, 1}, -kInf<T>), tri.p0,
                                       tri.p1, tri.p2, t, u, v));
        EXPECT_EQ(t, T(-1));
        // tfar is inclusive, tnear past the plane excludes it.
        EXPECT_TRUE(intersect_triangle(m, make_ray(Vec3<T>{0.25, 0.5, -1}, Vec3<T>{0, 0, 1}, T(0), T(1)), tri.p0,
                                       tri.p1, tri.p2, t, u, v));
        EXPECT_FALSE(intersect_triangle(m, make_ray(Vec3<T>{0.25, 0.5, -1}, Vec3<T>{0, 0, 1}, T(1.5)), tri.p0, tri.p1,
                                        tri.p2, t, u, v));
    }
}

// ---- Cones: axis z, base at z = 0 ------------------------------------------

KERNEL_TEST(CylinderHitFromSide) {
    const Vec3<T> base{0, 0, 0}, apex{0, 0, 2};
    T t = -1, s = -1;
    ASSERT_TRUE(intersect_cone(make_ray(Vec3<T>{-5, 0, 1}, Vec3<T>{1, 0, 0}), base, T(1), apex, T(1), t, s));
    EXPECT_EQ(t, T(4));
    EXPECT_EQ(s, T(0.5));
    ASSERT_TRUE(intersect_cone(make_ray(Vec3<T>{0, 5, 0.5}, Vec3<T>{0, -2, 0}), base, T(1), apex, T(1), t, s));
    EXPECT_EQ(t, T(2));
    EXPECT_EQ(s, T(0.25));
    // Oblique: from (-5, 0, 0) towards (0, 0, 2); enters where x = -1, at t = 0.8.
    ASSERT_TRUE(intersect_cone(make_ray(Vec3<T>{-5, 0, 0}, Vec3<T>{5, 0, 2}), base, T(1), apex, T(1), t, s));
    EXPECT_NEAR(double(t), 0.8, 4 * double(kEps<T>));
    EXPECT_NEAR(double(s), 0.8, 8 * double(kEps<T>));
}

KERNEL_TEST(OpenCylinderHasNoCaps) {
    const Vec3<T> base{0, 0, 0}, apex{0, 0, 2};
    T t = -1, s = -1;
    EXPECT_FALSE(intersect_cone(make_ray(Vec3<T>{0, 0, -5}, Vec3<T>{0, 0, 1}), base, T(1), apex, T(1), t, s));
    EXPECT_FALSE(intersect_cone(make_ray(Vec3<T>{0.5, -0.25, 7}, Vec3<T>{0, 0, -1}), base, T(1), apex, T(1), t, s));
    // Slightly tilted, so that it would cross a cap disc but leaves through the open end.
    EXPECT_FALSE(intersect_cone(make_ray(Vec3<T>{0, 0, -5}, Vec3<T>{0.01, 0, 1}), base, T(1), apex, T(1), t, s));
}

KERNEL_TEST(ConeWithPointedApex) {
    const Vec3<T> base{0, 0, 0}, apex{0, 0, 1};
    T t = -1, s = -1;
    // At height 0.5 the radius is 0.5.
    ASSERT_TRUE(intersect_cone(make_ray(Vec3<T>{-5, 0, 0.5}, Vec3<T>{1, 0, 0}), base, T(1), apex, T(0), t, s));
    EXPECT_EQ(t, T(4.5));
    EXPECT_EQ(s, T(0.5));
    // The same with base and apex swapped (radius 0 at the base end).
    ASSERT_TRUE(intersect_cone(make_ray(Vec3<T>{-5, 0, 0.5}, Vec3<T>{1, 0, 0}), apex, T(0), base, T(1), t, s));
    EXPECT_EQ(t, T(4.5));
    EXPECT_EQ(s, T(0.5));
}

KERNEL_TEST(ConeHitBeyondHeightMisses) {
    T t = -1, s = -1;
    const Vec3<T> o{0, 0, 0}, z1{0, 0, 1}, z2{0, 0, 2}, x{1, 0, 0};
    // Cylinder of height 2: the infinite cylinder is hit at z = 3, the segment is not.
    EXPECT_FALSE(intersect_cone(make_ray(Vec3<T>{-5, 0, 3}, x), o, T(1), z2, T(1), t, s));
    EXPECT_FALSE(intersect_cone(make_ray(Vec3<T>{-5, 0, -0.5}, x), o, T(1), z2, T(1), t, s));
    // Pointed cone: the mirrored nappe beyond the apex (z = 1.5, |r| = 0.5) is not part of it.
    EXPECT_FALSE(intersect_cone(make_ray(Vec3<T>{-5, 0, 1.5}, x), o, T(1), z1, T(0), t, s));
    // A ray that crosses the wall twice, first beyond the end (x = -1 at
    // t = 4, z = 3), then within it (x = 1 at t = 6, z = 1): the second counts.
    ASSERT_TRUE(intersect_cone(make_ray(Vec3<T>{-5, 0, 7}, Vec3<T>{1, 0, -1}), Vec3<T>{0, 0, 0}, T(1),
                               Vec3<T>{0, 0, 2}, T(1), t, s));
    EXPECT_EQ(t, T(6));
    EXPECT_EQ(s, T(0.5));
}

KERNEL_TEST(RayFromInsideCylinderHitsWall) {
    const Vec3<T> base{0, 0, 0}, apex{0, 0, 2};
    T t = -1, s = -1;
    ASSERT_TRUE(intersect_cone(make_ray(Vec3<T>{0, 0, 1}, Vec3<T>{1, 0, 0}), base, T(1), apex, T(1), t, s));
    EXPECT_EQ(t, T(1));
    EXPECT_EQ(s, T(0.5));
    ASSERT_TRUE(intersect_cone(make_ray(Vec3<T>{0.5, 0, 1}, Vec3<T>{-1, 0, 0}), base, T(1), apex, T(1), t, s));
    EXPECT_EQ(t, T(1.5));
    // tnear past the wall: nothing left.
    EXPECT_FALSE(intersect_cone(make_ray(Vec3<T>{0, 0, 1}, Vec3<T>{1, 0, 0}, T(1.5)), base, T(1), apex, T(1), t, s));
}

KERNEL_TEST(ConeObliqueAxisMatchesDoubleReference) {
    // A truncated cone on a tilted axis, against the same quadratic solved in
    // long double in the cone's own frame (axis along z).
    const Vec3<T> base{1, 2, 3}, apex{2, 1, 5};
    const T rb = 0.75, ra = 0.25;
    const Vec3<T> org{-3, 0.5, 4}, dir{4.5, 1, 0.25};  // close to the axis midpoint (1.5, 1.5, 4)
    T t = -1, s = -1;
    ASSERT_TRUE(intersect_cone(make_ray(org, dir), base, rb, apex, ra, t, s));
    // Reference: point p(t) = org + t dir; solve |p - base|^2 - ((p-base).w)^2 = r(s)^2.
    using L = long double;
    const L ax = 1, ay = -1, az = 2, h = std::sqrt(ax * ax + ay * ay + az * az);
    const L wx = ax / h, wy = ay / h, wz = az / h, k = (L(ra) - L(rb)) / h;
    auto f = [&](L tt) {
        const L px = L(org.x) + tt * L(dir.x) - 1, py = L(org.y) + tt * L(dir.y) - 2, pz = L(org.z) + tt * L(dir.z) - 3;
        const L sa = px * wx + py * wy + pz * wz;
        const L r = L(rb) + k * sa;
        return px * px + py * py + pz * pz - sa * sa - r * r;
    };
    // Bisect around the kernel's answer for the exact root.
    L lo = L(t) - 1e-3L, hi = L(t) + 1e-3L;
    ASSERT_LT(f(lo) * f(hi), 0);
    for (int i = 0; i < 200; ++i) {
        const L mid = (lo + hi) / 2;
        (f(lo) * f(mid) <= 0 ? hi : lo) = mid;
    }
    const double tol = std::is_same_v<T, float> ? 1e-5 : 1e-12;
    EXPECT_NEAR(double(t), double(lo), tol * double(lo));
}

KERNEL_TEST(ThinDistantConeIsAccurate) {
    // Thin cones seen from afar, from the camera rays of scenes/tree.nff
    // (pixel 331, 36 of 512) and scenes/rings.nff (pixel 461, 65), against the
    // same kernel in long double. With the origin 4.5 units from a cone of
    // radius 0.0018, |co|^2 - s0^2 - r0^2 must not lose r0^2 to cancellation.
    struct Case {
        Vec3f org, dir, base, apex;
        float rb, ra;
    };
    const Case cases[] = {
        {{0x1.2p+2f, 0x1.99999ap-2f, 0x1p+1f},
         {-0x1.0a34p+0f, 0x1.f2e75ep-6f, 0x1.f312c4p-3f},
         {-0x1.057c92p-2f, 0x1.10d49ap-1f, 0x1.8cd9e8p+1f},
         {-0x1.fe4efp-3f, 0x1.13eb5cp-1f, 0x1.8eeccp+1f},
         0x1.e03c16p-10f,
         0x1.41c218p-10f},
        {{-0x1p+0f, -0x1.4e7b0cp+1f, 0x1p-1f},
         {0x1.55265ep-2f, 0x1p+0f, 0x1.3c3f98p-2f},
         {0x1.b03444p+2f, 0x1.20c154p+4f, 0x1.9f5326p+2f},
         {0x1.6d967cp+2f, 0x1.1e559cp+4f, 0x1.b2af5p+2f},
         0x1.2f9874p-4f,
         0x1.2f9874p-4f},
    };
    using L = long double;
    for (const Case& c : cases) {
        Ray<L> rl;
        rl.org = Vec3<L>(c.org);
        rl.dir = Vec3<L>(c.dir);
        rl.tnear = 1;
        L tl = -1, sl = -1;
        const bool want = intersect_cone(rl, Vec3<L>(c.base), L(c.rb), Vec3<L>(c.apex), L(c.ra), tl, sl);
        T t = -1, s = -1;
        const bool got = intersect_cone(make_ray(Vec3<T>(c.org), Vec3<T>(c.dir), T(1)), Vec3<T>(c.base), T(c.rb),
                                        Vec3<T>(c.apex), T(c.ra), t, s);
        EXPECT_EQ(got, want) << "t " << double(t) << ", long double " << (want ? double(tl) : -1.0);
        if (got && want) {
            EXPECT_NEAR(double(t), double(tl), 1e-5 * double(tl));
        }
    }
}

KERNEL_TEST(ConeNormalIsGradientOfSurface) {
    // F(p) = |p - axis point|^2 - r(s)^2 vanishes on the surface; its gradient
    // is the (unnormalised) normal. Compare directions with central differences
    // of F in long double, at points all around a tilted truncated cone.
    const Vec3<T> base{1, 2, 3}, apex{2, 1, 5};
    const T rb = 0.75, ra = 0.25;
    using L = long double;
    const L bx = 1, by = 2, bz = 3, ax = 1, ay = -1, az = 2, h = std::sqrt(6.0L);
    const L wx = ax / h, wy = ay / h, wz = az / h, k = (L(ra) - L(rb)) / h;
    auto F = [&](L x, L y, L z) {
        x -= bx, y -= by, z -= bz;
        const L sa = x * wx + y * wy + z * wz;
        const L r = L(rb) + k * sa;
        return x * x + y * y + z * z - sa * sa - r * r;
    };
    // Two unit vectors perpendicular to the axis.
    const L e1x = 1 / std::sqrt(2.0L), e1y = 1 / std::sqrt(2.0L), e1z = 0;  // (1,1,0)/sqrt2 . (1,-1,2) = 0
    const L e2x = wy * e1z - wz * e1y, e2y = wz * e1x - wx * e1z, e2z = wx * e1y - wy * e1x;
    const double tol = std::is_same_v<T, float> ? 2e-6 : 1e-12;
    for (L frac : {0.1L, 0.5L, 0.9L}) {
        for (L ang : {0.0L, 1.0L, 2.5L, 4.0L, 5.5L}) {
            const L sa = frac * h, r = L(rb) + k * sa;
            const L ux = std::cos(ang) * e1x + std::sin(ang) * e2x, uy = std::cos(ang) * e1y + std::sin(ang) * e2y,
                    uz = std::cos(ang) * e1z + std::sin(ang) * e2z;
            const L px = bx + wx * sa + ux * r, py = by + wy * sa + uy * r, pz = bz + wz * sa + uz * r;
            const Vec3<T> n = cone_normal(Vec3<T>{T(px), T(py), T(pz)}, base, rb, apex, ra);
            const L d = 1e-6L;
            const L gx = (F(px + d, py, pz) - F(px - d, py, pz)) / (2 * d);
            const L gy = (F(px, py + d, pz) - F(px, py - d, pz)) / (2 * d);
            const L gz = (F(px, py, pz + d) - F(px, py, pz - d)) / (2 * d);
            const L gl = std::sqrt(gx * gx + gy * gy + gz * gz);
            const L nl = std::sqrt(L(n.x) * n.x + L(n.y) * n.y + L(n.z) * n.z);
            // Parallel and pointing the same way: |n/|n| - g/|g|| small.
            const L dx = L(n.x) / nl - gx / gl, dy = L(n.y) / nl - gy / gl, dz = L(n.z) / nl - gz / gl;
            EXPECT_LT(double(std::sqrt(dx * dx + dy * dy + dz * dz)), 20 * tol) << "frac " << double(frac) << " ang "
                                                                             << double(ang);
            // Perpendicular to the generator line through p (base rim to apex rim).
            const L gnx = ax + ux * (L(ra) - L(rb)), gny = ay + uy * (L(ra) - L(rb)), gnz = az + uz * (L(ra) - L(rb));
            const L gnl = std::sqrt(gnx * gnx + gny * gny + gnz * gnz);
            EXPECT_LT(double(std::fabs((L(n.x) * gnx + L(n.y) * gny + L(n.z) * gnz) / (nl * gnl))), 20 * tol);
            // Outward: along the radial direction u.
            EXPECT_GT(double(L(n.x) * ux + L(n.y) * uy + L(n.z) * uz), 0.0);
        }
    }
}

// ---- Slab test: box [-1, 1]^3 ---------------------------------------------

template <class T>
Box3<T> unit_box() {
    Box3<T> b;
    b.lo = {-1, -1, -1};
    b.hi = {1, 1, 1};
    return b;
}

template <class T>
bool slab(const Vec3<T>& org, const Vec3<T>& dir, T& entry, T tnear = T(0), T tfar = kInf<T>) {
    return intersect_aabb(org, reciprocal(dir), unit_box<T>(), tnear, tfar, entry);
}

KERNEL_TEST(AabbHitMissAndEntry) {
    T entry = -1;
    ASSERT_TRUE(slab(Vec3<T>{-5, 0, 0}, Vec3<T>{1, 0.125, -0.125}, entry));
    EXPECT_EQ(entry, T(4));
    ASSERT_TRUE(slab(Vec3<T>{0, 0, 9}, Vec3<T>{0.125, 0.125, -2}, entry));
    EXPECT_EQ(entry, T(4));
    EXPECT_FALSE(slab(Vec3<T>{-5, 2, 0}, Vec3<T>{1, 0, 0}, entry));
    EXPECT_FALSE(slab(Vec3<T>{-5, 0, 0}, Vec3<T>{-1, 0, 0}, entry));  // box behind
    EXPECT_FALSE(slab(Vec3<T>{-5, -5, 0}, Vec3<T>{1, 0.5, 0}, entry));  // passes the corner
    // Inside: entry is clamped to tnear.
    ASSERT_TRUE(slab(Vec3<T>{0, 0, 0}, Vec3<T>{1, 1, 1}, entry, T(0.25)));
    EXPECT_EQ(entry, T(0.25));
    // tnear / tfar clip the slab interval [4, 6].
    EXPECT_FALSE(slab(Vec3<T>{-5, 0, 0}, Vec3<T>{1, 0, 0}, entry, T(0), T(3.5)));
    EXPECT_TRUE(slab(Vec3<T>{-5, 0, 0}, Vec3<T>{1, 0, 0}, entry, T(0), T(4)));
    EXPECT_FALSE(slab(Vec3<T>{-5, 0, 0}, Vec3<T>{1, 0, 0}, entry, T(6.5)));
}

KERNEL_TEST(AabbRayParallelToSlab) {
    T entry = -1;
    // Zero y and z: inside the y and z slabs -> hit; outside -> miss.
    ASSERT_TRUE(slab(Vec3<T>{-5, 0.5, -0.5}, Vec3<T>{1, 0, 0}, entry));
    EXPECT_EQ(entry, T(4));
    EXPECT_FALSE(slab(Vec3<T>{-5, 1.5, 0}, Vec3<T>{1, 0, 0}, entry));
    EXPECT_FALSE(slab(Vec3<T>{-5, 0, -1.5}, Vec3<T>{1, 0, 0}, entry));
    // Negative zeros give -inf reciprocals; the answers must not change.
    ASSERT_TRUE(slab(Vec3<T>{-5, 0.5, -0.5}, Vec3<T>{1, -0.0, -0.0}, entry));
    EXPECT_EQ(entry, T(4));
    EXPECT_FALSE(slab(Vec3<T>{-5, 1.5, 0}, Vec3<T>{1, -0.0, -0.0}, entry));
    EXPECT_FALSE(slab(Vec3<T>{-5, 0, -1.5}, Vec3<T>{1, -0.0, 0}, entry));
    ASSERT_TRUE(slab(Vec3<T>{5, 0.5, -0.5}, Vec3<T>{-1, -0.0, 0}, entry));
    EXPECT_EQ(entry, T(4));
}

KERNEL_TEST(AabbOriginOnSlabPlaneWithZeroDirection) {
    // aabb.h: "An origin exactly on a slab plane with a parallel direction ...
    // counts as inside that slab". That must hold for both planes and for both
    // signs of zero: a ray in the plane y = 1 touches a sphere of radius 1 at
    // the origin, and the brute-force oracle reports that hit.
    for (T y : {T(1), T(-1)}) {
        for (T zero : {T(0), -T(0)}) {
            SCOPED_TRACE(::testing::Message() << "y = " << y << ", dir.y = " << (std::signbit(zero) ? "-0" : "+0"));
            T entry = -1;
            EXPECT_TRUE(slab(Vec3<T>{-5, y, 0}, Vec3<T>{1, zero, 0}, entry));
            EXPECT_EQ(entry, T(4));
            EXPECT_TRUE(slab(Vec3<T>{-5, y, 0}, Vec3<T>{1, zero, 0}, entry, T(0), T(10)));
            EXPECT_EQ(entry, T(4));
            // On an edge of the box (two planes at once).
            EXPECT_TRUE(slab(Vec3<T>{-5, y, y}, Vec3<T>{1, zero, zero}, entry, T(0), T(10)));
            EXPECT_EQ(entry, T(4));
        }
    }
    // And just outside the plane it is a miss whatever the sign.
    T entry = -1;
    const T out = T(1) + T(2) * kEps<T>;
    EXPECT_FALSE(slab(Vec3<T>{-5, out, 0}, Vec3<T>{1, T(0), 0}, entry));
    EXPECT_FALSE(slab(Vec3<T>{-5, out, 0}, Vec3<T>{1, -T(0), 0}, entry));
}

KERNEL_TEST(AabbIsConservativeAtCorners) {
    // A ray aimed exactly at a box corner touches the box. A triangle whose
    // vertex makes that corner is hit by the (inclusive) triangle test, so a
    // BVH whose slab test culled the box here would lose the hit: the test
    // must round in the box's favour (Ize, "Robust BVH Ray Traversal", JCGT
    // 2013). scenes/mount.nff has such rays (AccelOracle adversarial set).
    Box3<T> box;
    box.lo = {-1, T(-0.75), T(0.3)};
    box.hi = {T(0.6), T(1.25), T(2.1)};
    std::mt19937 rng(5);
    std::uniform_real_distribution<T> u(-4, 4);
    int culled = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3<T> org{u(rng), u(rng), u(rng)};
        const unsigned c = rng() % 8;
        const Vec3<T> corner{(c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y,
                             (c & 4) ? box.hi.z : box.lo.z};
        T entry;
        if (!intersect_aabb(org, reciprocal(corner - org), box, T(0), kInf<T>, entry)) ++culled;
    }
    EXPECT_EQ(culled, 0) << "of 2000 rays aimed at box corners";
}

KERNEL_TEST(AabbEntryForEveryFace) {
    for (int axis = 0; axis < 3; ++axis) {
        for (T sign : {T(1), T(-1)}) {
            Vec3<T> org{T(0.25), T(-0.5), T(0.125)}, dir{};
            org[axis] = -sign * T(3);
            dir[axis] = sign * T(0.5);
            T entry = -1;
            ASSERT_TRUE(slab(org, dir, entry));
            EXPECT_EQ(entry, T(4));  // 2 units to the face at speed 0.5
        }
    }
}

// ---- Quadratic ---------------------------------------------------------------

KERNEL_TEST(QuadraticStableOnCancellation) {
    // t^2 - 2e4 t + 1 = 0 (b = -1e4 in the half-coefficient form): the small
    // root ~5e-5 is what the textbook formula loses to cancellation.
    const T a = 1, b = -1e4, c = 1;
    T t0 = -1, t1 = -1;
    ASSERT_TRUE(solve_quadratic_half(a, b, c, t0, t1));
    using L = long double;
    const L disc = std::sqrt(L(b) * L(b) - L(a) * L(c));
    const L big = (-L(b) + disc) / L(a), small = L(c) / (L(a) * big);
    EXPECT_LE(std::fabs((L(t0) - small) / small), 2 * L(kEps<T>));
    EXPECT_LE(std::fabs((L(t1) - big) / big), 2 * L(kEps<T>));
    // The textbook formula, in the same precision, is much worse: the check
    // above is therefore able to fail.
    const T naive = (-b - std::sqrt(b * b - a * c)) / a;
    EXPECT_GT(std::fabs((L(naive) - small) / small), 100 * L(kEps<T>));
    // Same with b > 0 (both roots negative).
    ASSERT_TRUE(solve_quadratic_half(a, -b, c, t0, t1));
    EXPECT_LE(std::fabs((L(t1) + small) / small), 2 * L(kEps<T>));
    EXPECT_LE(std::fabs((L(t0) + big) / big), 2 * L(kEps<T>));
}

KERNEL_TEST(QuadraticSpecialCases) {
    T t0 = -7, t1 = -7;
    EXPECT_FALSE(solve_quadratic_half(T(1), T(0), T(1), t0, t1));  // t^2 + 1
    EXPECT_FALSE(solve_quadratic_half(T(0), T(1), T(1), t0, t1));  // not a quadratic
    EXPECT_FALSE(solve_quadratic_half(T(1), std::numeric_limits<T>::quiet_NaN(), T(1), t0, t1));
    ASSERT_TRUE(solve_quadratic_half(T(1), T(0), T(0), t0, t1));  // double root at 0
    EXPECT_EQ(t0, T(0));
    EXPECT_EQ(t1, T(0));
    ASSERT_TRUE(solve_quadratic_half(T(2), T(-3), T(-8), t0, t1));  // 2t^2 - 6t - 8 = 2 (t-4)(t+1)
    EXPECT_EQ(t0, T(-1));
    EXPECT_EQ(t1, T(4));
    T t = -7;
    EXPECT_TRUE(nearest_root_in(T(-1), T(4), T(0), kInf<T>, t));
    EXPECT_EQ(t, T(4));
    EXPECT_FALSE(nearest_root_in(T(-1), T(4), T(4.5), kInf<T>, t));
}

}  // namespace
}  // namespace raypack
