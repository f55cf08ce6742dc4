// Packet triangle kernels (kernels/triangle.h), for the three variants and
// both shapes (K rays against one triangle; one ray against M = K triangles
// in SoA):
// 1. every lane equals the width-1 answer bit for bit (hit, t, u, v) on 2^20
//    seeded random rays per shape plus adversarial ones: the lanes run the
//    same operations, so nothing less is acceptable;
// 2. the width-1 float answers against the double instantiation: t within a
//    running-error bound, and every hit/miss difference explained (a point
//    within rounding of an edge, a determinant within rounding of zero, or t
//    within rounding of tnear/tfar);
// 3. rays aimed at shared edges and vertices of closed meshes never pass
//    through the watertight test (Woop, Benthin & Wald, JCGT 2013).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "accel/prims/triangle_edges.h"
#include "kernels/triangle.h"

namespace raypack {
namespace {

constexpr TriangleMethod kMethods[] = {TriangleMethod::Moeller, TriangleMethod::Watertight, TriangleMethod::Plane};

const char* name(TriangleMethod m) {
    switch (m) {
        case TriangleMethod::Moeller: return "moeller";
        case TriangleMethod::Watertight: return "watertight";
        case TriangleMethod::Plane: return "plane";
    }
    return "?";
}

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kEpsF = std::numeric_limits<float>::epsilon();  // 2^-23

struct TestRay {
    Vec3f org, dir;
    float tnear = 0.0f, tfar = kInf;
};
struct Tri {
    Vec3f p0, p1, p2;
};

std::string str(const Vec3f& v) {
    char b[96];
    std::snprintf(b, sizeof b, "(%a, %a, %a)", double(v.x), double(v.y), double(v.z));
    return b;
}
std::string str(const TestRay& r, const Tri& t) {
    char b[32];
    std::snprintf(b, sizeof b, " [%a, %a]", double(r.tnear), double(r.tfar));
    return "org " + str(r.org) + " dir " + str(r.dir) + b + " tri " + str(t.p0) + " " + str(t.p1) + " " + str(t.p2);
}

// ---- Cases: ray-triangle pairs as SoA; a packet's lanes are consecutive pairs

struct Cases {
    enum { OX, OY, OZ, DX, DY, DZ, TN, TF, AX, AY, AZ, BX, BY, BZ, CX, CY, CZ, kFields };
    std::vector<float> f[kFields];

    std::size_t size() const { return f[0].size(); }
    void clear() {
        for (auto& v : f) v.clear();
    }
    void add(const TestRay& r, const Tri& t) {
        const float v[kFields] = {r.org.x, r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z, r.tnear, r.tfar, t.p0.x,
                                  t.p0.y,  t.p0.z,  t.p1.x,  t.p1.y,  t.p1.z,  t.p2.x,  t.p2.y,  t.p2.z};
        for (int k = 0; k < kFields; ++k) f[k].push_back(v[k]);
    }
    TestRay ray(std::size_t i) const {
        return {{f[OX][i], f[OY][i], f[OZ][i]}, {f[DX][i], f[DY][i], f[DZ][i]}, f[TN][i], f[TF][i]};
    }
    Tri tri(std::size_t i) const {
        return {{f[AX][i], f[AY][i], f[AZ][i]}, {f[BX][i], f[BY][i], f[BZ][i]}, {f[CX][i], f[CY][i], f[CZ][i]}};
    }
};

struct Answers {
    std::vector<std::uint8_t> hit;
    std::vector<float> t, u, v;
};

template <class F>
mask_of<F> intersect(TriangleMethod m, mask_of<F> valid, const Vec3<F>& o, const Vec3<F>& d, const F& tn,
                     const F& tf, const Vec3<F>& p0, const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    switch (m) {
        case TriangleMethod::Moeller: return intersect_triangle_moeller<F>(valid, o, d, tn, tf, p0, p1, p2, t, u, v);
        case TriangleMethod::Watertight:
            return intersect_triangle_watertight<F>(valid, o, d, tn, tf, p0, p1, p2, t, u, v);
        case TriangleMethod::Plane: return intersect_triangle_plane<F>(valid, o, d, tn, tf, p0, p1, p2, t, u, v);
    }
    return mask_of<F>(false);
}

/// Lanes active where act[i] > 0.
template <class F>
mask_of<F> make_mask(const float* act) {
    if constexpr (std::is_floating_point_v<F>) return *act > 0.0f;
    else return F::load_unaligned(act) > F(0.0f);
}

/// The answers of K-wide packets over consecutive pairs. With `partial`,
/// lane l of packet i starts inactive when (i + 3l) % 5 == 0.
template <int K>
Answers run_lanes(TriangleMethod m, const Cases& c, bool partial = false) {
    using F = vfloat<K>;
    const std::size_t n = c.size();
    Answers a;
    a.hit.assign(n, 0);
    a.t.assign(n, 0.0f);
    a.u.assign(n, 0.0f);
    a.v.assign(n, 0.0f);
    for (std::size_t i = 0; i + K <= n; i += K) {
        auto L = [&](int field) { return load_lanes<F>(&c.f[field][i]); };
        const Vec3<F> o{L(Cases::OX), L(Cases::OY), L(Cases::OZ)}, d{L(Cases::DX), L(Cases::DY), L(Cases::DZ)};
        const Vec3<F> p0{L(Cases::AX), L(Cases::AY), L(Cases::AZ)}, p1{L(Cases::BX), L(Cases::BY), L(Cases::BZ)},
            p2{L(Cases::CX), L(Cases::CY), L(Cases::CZ)};
        float act[K];
        for (int l = 0; l < K; ++l) act[l] = partial && (i / K + 3 * std::size_t(l)) % 5 == 0 ? 0.0f : 1.0f;
        F t = F(0.0f), u = F(0.0f), v = F(0.0f);
        const std::uint32_t bits =
            mask_bits(intersect<F>(m, make_mask<F>(act), o, d, L(Cases::TN), L(Cases::TF), p0, p1, p2, t, u, v));
        for (int l = 0; l < K; ++l) {
            if (!((bits >> l) & 1u)) continue;
            a.hit[i + std::size_t(l)] = 1;
            a.t[i + std::size_t(l)] = lane(t, l);
            a.u[i + std::size_t(l)] = lane(u, l);
            a.v[i + std::size_t(l)] = lane(v, l);
        }
    }
    return a;
}

bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

/// Packet answers `got` equal the width-1 answers `want` bit for bit; with
/// `partial`, lanes started inactive must come back missed.
::testing::AssertionResult same_answers(const Cases& c, const Answers& want, const Answers& got, int K,
                                        bool partial = false) {
    std::size_t bad = 0;
    std::string first;
    for (std::size_t i = 0; i < c.size(); ++i) {
        bool h = want.hit[i] != 0;
        if (partial && ((i / std::size_t(K)) + 3 * (i % std::size_t(K))) % 5 == 0) h = false;
        bool ok = h == (got.hit[i] != 0);
        if (ok && h)
            ok = same_bits(want.t[i], got.t[i]) && same_bits(want.u[i], got.u[i]) && same_bits(want.v[i], got.v[i]);
        if (ok) continue;
        if (++bad <= 3) {
            char b[160];
            std::snprintf(b, sizeof b, "\n  pair %zu: width 1 %d t=%a u=%a v=%a, lane %d t=%a u=%a v=%a\n    ", i,
                          int(h), double(want.t[i]), double(want.u[i]), double(want.v[i]), int(got.hit[i]),
                          double(got.t[i]), double(got.u[i]), double(got.v[i]));
            first += b + str(c.ray(i), c.tri(i));
        }
    }
    if (bad == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << bad << " of " << c.size() << " lanes differ from width 1:" << first;
}

// ---- Seeded generators -------------------------------------------------------

class Gen {
public:
    explicit Gen(unsigned seed) : rng_(seed) {}
    float uni(float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng_); }
    float pow2(float a, float b) { return std::exp2(uni(a, b)); }
    int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
    Vec3f vec(float a, float b) { return {uni(a, b), uni(a, b), uni(a, b)}; }
    Vec3f unit() {
        for (;;) {
            const Vec3f v = vec(-1.0f, 1.0f);
            const float l = dot(v, v);
            if (l > 1e-4f && l <= 1.0f) return v / std::sqrt(l);
        }
    }

private:
    std::mt19937 rng_;
};

Tri random_triangle(Gen& g) {
    const Vec3f c = g.vec(-4.0f, 4.0f);
    const float s = g.pow2(-3.0f, 2.0f);
    return {c + g.vec(-1.0f, 1.0f) * s, c + g.vec(-1.0f, 1.0f) * s, c + g.vec(-1.0f, 1.0f) * s};
}

Vec3f point_on(const Tri& t, float b1, float b2) { return t.p0 + (t.p1 - t.p0) * b1 + (t.p2 - t.p0) * b2; }

/// A ray from a random origin through `target` (at t ~ 1/scale), with a
/// direction of random length and, for some, an interval that ends before
/// or starts after the target, or reaches back to -inf. With `axis` >= 0 the
/// direction's largest component is on that axis (with a random sign).
TestRay ray_through(Gen& g, const Vec3f& target, int axis = -1, float sign = 1.0f) {
    Vec3f away = g.unit();
    if (axis >= 0) away = away * 0.5f, away[axis] = sign * g.uni(1.0f, 2.0f);
    const Vec3f org = target + away * g.pow2(-2.0f, 4.0f);
    const float scale = g.pow2(-3.0f, 3.0f);
    TestRay r{org, (target - org) * scale};
    const float x = g.uni(0.0f, 1.0f), t_hit = 1.0f / scale;
    if (x < 0.1f) r.tfar = g.uni(0.0f, 2.0f) * t_hit;
    else if (x < 0.15f) r.tnear = g.uni(0.0f, 2.0f) * t_hit;
    else if (x < 0.2f) r.tnear = -kInf, r.dir = -r.dir;
    return r;
}

constexpr std::size_t kRandomRays = std::size_t(1) << 20;  // per shape
constexpr std::size_t kChunk = std::size_t(1) << 16;       // pairs generated at a time

/// Chunk `k` of the K-rays shape: 4096 random triangles, 16 rays each, aimed
/// at barycentrics in [-0.1, 1]^2 (about 40% inside). Every other group of
/// 16 shares the axis of its rays' largest direction component (as coherent
/// packets do; the watertight test then takes its uniform-axis path), the
/// others have random directions (lanes with different axes).
void packet_chunk(std::size_t k, Cases& c) {
    c.clear();
    Gen g(unsigned(1000 + k));
    for (std::size_t i = 0; i < kChunk / 16; ++i) {
        const Tri tri = random_triangle(g);
        const int axis = i % 2 ? g.pick(3) : -1;
        const float sign = g.pick(2) ? 1.0f : -1.0f;
        for (int r = 0; r < 16; ++r) {
            const float b1 = g.uni(-0.1f, 1.0f), b2 = g.uni(-0.1f, 1.0f);
            c.add(ray_through(g, point_on(tri, b1, b2), axis, sign), tri);
        }
    }
}

/// Chunk `k` of the 1xM shape: kChunk / M random rays, each against M random
/// triangles placed so that the ray crosses their plane at barycentrics in
/// [-0.1, 1]^2.
void block_chunk(std::size_t k, int M, Cases& c) {
    c.clear();
    Gen g(unsigned(5000 + 64 * k + unsigned(M)));
    for (std::size_t i = 0; i < kChunk / std::size_t(M); ++i) {
        const Vec3f target = g.vec(-4.0f, 4.0f);
        const TestRay ray = ray_through(g, target);
        for (int j = 0; j < M; ++j) {
            const float s = g.pow2(-3.0f, 2.0f);
            const Tri q{g.vec(-1.0f, 1.0f) * s, g.vec(-1.0f, 1.0f) * s, g.vec(-1.0f, 1.0f) * s};
            const float b1 = g.uni(-0.1f, 1.0f), b2 = g.uni(-0.1f, 1.0f);
            const Vec3f shift = target - point_on(q, b1, b2);
            c.add(ray, {q.p0 + shift, q.p1 + shift, q.p2 + shift});
        }
    }
}

// ---- Adversarial cases, 16 rays per triangle -----------------------------------

std::vector<Tri> adversarial_triangles(Gen& g) {
    std::vector<Tri> tris;
    for (int i = 0; i < 24; ++i) tris.push_back(random_triangle(g));
    for (int axis = 0; axis < 3; ++axis) {
        for (int i = 0; i < 3; ++i) {  // in a plane x, y or z = const
            Tri t = random_triangle(g);
            const float c = t.p0[axis];
            t.p1[axis] = c, t.p2[axis] = c;
            tris.push_back(t);
        }
    }
    for (int i = 0; i < 6; ++i) {  // small integer coordinates
        auto ip = [&] { return Vec3f{float(g.pick(9) - 4), float(g.pick(9) - 4), float(g.pick(9) - 4)}; };
        tris.push_back({ip(), ip(), ip()});
    }
    // Degenerate: exactly collinear, collinear up to rounding, coincident
    // vertices, a point, and a sliver.
    tris.push_back({{0, 0, 0}, {1, 1, 1}, {3, 3, 3}});
    const Tri r = random_triangle(g);
    tris.push_back({r.p0, r.p1, r.p0 + (r.p1 - r.p0) * 2.0f});
    tris.push_back({r.p0, r.p0, r.p2});
    tris.push_back({r.p1, r.p1, r.p1});
    tris.push_back({r.p0, r.p1, r.p0 + (r.p1 - r.p0) * 0.5f + Vec3f{0, 0, 1e-6f}});
    return tris;
}

/// Targets on the triangle's boundary: its vertices and points on its
/// edges computed as p_a + s (p_b - p_a) in float.
Vec3f boundary_point(Gen& g, const Tri& t, int i) {
    const Vec3f p[3] = {t.p0, t.p1, t.p2};
    const int a = i % 3, b = (i + 1) % 3;
    switch ((i / 3) % 4) {
        case 0: return p[a];
        case 1: return p[a] + (p[b] - p[a]) * 0.5f;
        case 2: return p[a] + (p[b] - p[a]) * g.uni(0.0f, 1.0f);
        default: return point_on(t, g.uni(0.0f, 1.0f), 0.0f);
    }
}

Cases adversarial_cases(unsigned seed) {
    Gen g(seed);
    Cases c;
    for (const Tri& tri : adversarial_triangles(g)) {
        const Vec3f e1 = tri.p1 - tri.p0, e2 = tri.p2 - tri.p0;
        const Vec3f n = cross(e1, e2);
        const float nl = std::sqrt(dot(n, n));
        const Vec3f nh = nl > 0 ? n / nl : Vec3f{0, 0, 1};
        for (int round = 0; round < 4; ++round) {
            // Axis-parallel directions with +-0 in the other components, aimed
            // at vertices, edge points and interior points: the origin is
            // target - dir * s, exact in the two zero components.
            for (int i = 0; i < 16; ++i) {
                Vec3f d{(i & 4) ? -0.0f : 0.0f, (i & 8) ? -0.0f : 0.0f, (i & 1) ? -0.0f : 0.0f};
                d[i % 3] = (i / 3) % 2 ? -g.pow2(-2.0f, 2.0f) : g.pow2(-2.0f, 2.0f);
                const Vec3f target = i < 12 ? boundary_point(g, tri, i) : point_on(tri, g.uni(0, 1), g.uni(0, 0.5f));
                c.add({target - d * g.pow2(-1.0f, 3.0f), d}, tri);
            }
            // Random directions with one or two components +-0.
            for (int i = 0; i < 16; ++i) {
                Vec3f d = g.unit() * g.pow2(-2.0f, 2.0f);
                d[i % 3] = (i & 4) ? -0.0f : 0.0f;
                if (i & 8) d[(i + 1) % 3] = (i & 2) ? -0.0f : 0.0f;
                const Vec3f target = (i & 1) ? boundary_point(g, tri, i) : point_on(tri, g.uni(0, 1), g.uni(0, 0.5f));
                c.add({target - d * g.pow2(-1.0f, 3.0f), d}, tri);
            }
            // Rays through edges and vertices from random origins.
            for (int i = 0; i < 16; ++i) c.add(ray_through(g, boundary_point(g, tri, i)), tri);
            // Grazing rays: origin in the triangle's plane (up to rounding),
            // direction in the plane or tilted out of it by a few ulps.
            for (int i = 0; i < 16; ++i) {
                const Vec3f o = point_on(tri, g.uni(-0.5f, 1.5f), g.uni(-0.5f, 1.5f));
                Vec3f d = e1 * g.uni(-1.0f, 1.0f) + e2 * g.uni(-1.0f, 1.0f);
                const float tilt[4] = {0.0f, 1e-7f, -1e-6f, 1e-3f};
                d = d + nh * (tilt[i % 4] * std::sqrt(dot(d, d)));
                TestRay r{o, d};
                if (i & 4) r.tnear = -kInf;
                c.add(r, tri);
            }
            // Rays starting on the triangle (inside or on an edge), tnear = 0.
            for (int i = 0; i < 16; ++i) {
                const float b1 = (i & 3) == 0 ? 0.0f : g.uni(0.0f, 0.5f), b2 = (i & 3) == 1 ? 0.0f : g.uni(0, 0.5f);
                c.add({point_on(tri, b1, b2), g.unit() * g.pow2(-2.0f, 2.0f)}, tri);
            }
        }
    }
    return c;
}

/// The 1xM shape of the adversarial cases: each ray against its triangle in
/// the six vertex orders, then the triangles of the next M - 6 pairs.
Cases adversarial_blocks(const Cases& a, int M) {
    Cases c;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const TestRay r = a.ray(i);
        const Tri t = a.tri(i);
        const Tri orders[6] = {t, {t.p1, t.p2, t.p0}, {t.p2, t.p0, t.p1}, {t.p0, t.p2, t.p1}, {t.p2, t.p1, t.p0},
                               {t.p1, t.p0, t.p2}};
        for (int j = 0; j < M; ++j) c.add(r, j < 6 ? orders[j] : a.tri((i + std::size_t(j)) % a.size()));
    }
    return c;
}

// ---- The typed test over K ------------------------------------------------------

/// testing::Types of the widths compiled in (kWidthCompiled), in order.
template <class Have, class... Rest>
struct CompiledWidths {
    using type = Have;
};
template <class... Have, class K, class... Rest>
struct CompiledWidths<::testing::Types<Have...>, K, Rest...> {
    using type = typename CompiledWidths<std::conditional_t<kWidthCompiled<K::value>, ::testing::Types<Have..., K>,
                                                            ::testing::Types<Have...>>,
                                         Rest...>::type;
};
using Widths = CompiledWidths<::testing::Types<>, std::integral_constant<int, 1>, std::integral_constant<int, 4>,
                              std::integral_constant<int, 8>, std::integral_constant<int, 16>>::type;

template <class W>
class PacketTriangle : public ::testing::Test {};
TYPED_TEST_SUITE(PacketTriangle, Widths);

TYPED_TEST(PacketTriangle, RaysAgainstOneTriangleEqualWidthOne) {
    constexpr int K = TypeParam::value;
    Cases c;
    std::size_t hits[3] = {};
    for (std::size_t k = 0; k < kRandomRays / kChunk; ++k) {
        packet_chunk(k, c);
        for (int mi = 0; mi < 3; ++mi) {
            const TriangleMethod m = kMethods[mi];
            const Answers want = run_lanes<1>(m, c);
            ASSERT_TRUE(same_answers(c, want, run_lanes<K>(m, c), K)) << name(m) << ", chunk " << k;
            for (auto h : want.hit) hits[mi] += h;
        }
    }
    for (int mi = 0; mi < 3; ++mi) {
        // About 40% of the rays are aimed inside, some end before the triangle.
        EXPECT_GT(hits[mi], kRandomRays / 4) << name(kMethods[mi]);
        EXPECT_LT(hits[mi], kRandomRays / 2) << name(kMethods[mi]);
    }
}

TYPED_TEST(PacketTriangle, OneRayAgainstTriangleBlockEqualsWidthOne) {
    constexpr int K = TypeParam::value;
    Cases c;
    for (std::size_t k = 0; k < kRandomRays * K / kChunk; ++k) {
        block_chunk(k, K, c);
        for (TriangleMethod m : kMethods)
            ASSERT_TRUE(same_answers(c, run_lanes<1>(m, c), run_lanes<K>(m, c), K)) << name(m) << ", chunk " << k;
    }
}

TYPED_TEST(PacketTriangle, AdversarialRaysEqualWidthOne) {
    constexpr int K = TypeParam::value;
    const Cases rays = adversarial_cases(77);
    const Cases blocks = adversarial_blocks(rays, K);
    for (TriangleMethod m : kMethods) {
        SCOPED_TRACE(name(m));
        const Answers want = run_lanes<1>(m, rays);
        EXPECT_TRUE(same_answers(rays, want, run_lanes<K>(m, rays), K)) << "K rays x 1 triangle";
        EXPECT_TRUE(same_answers(rays, want, run_lanes<K>(m, rays, true), K, true)) << "with inactive lanes";
        EXPECT_TRUE(same_answers(blocks, run_lanes<1>(m, blocks), run_lanes<K>(m, blocks), K)) << "1 ray x M";
    }
}

/// Moeller with u, v deferred (MoellerUV) at width K: the same lanes and t as
/// the immediate form, and u(), v() its u, v bit for bit.
template <int K>
::testing::AssertionResult deferred_matches_immediate(const Cases& c) {
    using F = vfloat<K>;
    const Answers want = run_lanes<K>(TriangleMethod::Moeller, c);
    std::size_t bad = 0, hits = 0;
    for (std::size_t i = 0; i + K <= c.size(); i += K) {
        auto L = [&](int field) { return load_lanes<F>(&c.f[field][i]); };
        const Vec3<F> o{L(Cases::OX), L(Cases::OY), L(Cases::OZ)}, d{L(Cases::DX), L(Cases::DY), L(Cases::DZ)};
        const Vec3<F> p0{L(Cases::AX), L(Cases::AY), L(Cases::AZ)}, p1{L(Cases::BX), L(Cases::BY), L(Cases::BZ)},
            p2{L(Cases::CX), L(Cases::CY), L(Cases::CZ)};
        F t = F(0.0f);
        MoellerUV<F> uv{F(0.0f), F(0.0f), F(0.0f)};
        const std::uint32_t bits = mask_bits(
            intersect_triangle_moeller<F>(mask_of<F>(true), o, d, L(Cases::TN), L(Cases::TF), p0, p1, p2, t, uv));
        const F u = uv.u(), v = uv.v();
        for (int l = 0; l < K; ++l) {
            const std::size_t j = i + std::size_t(l);
            const bool h = (bits >> l) & 1u;
            hits += h;
            bad += h != (want.hit[j] != 0) ||
                   (h && !(same_bits(lane(t, l), want.t[j]) && same_bits(lane(u, l), want.u[j]) &&
                           same_bits(lane(v, l), want.v[j])));
        }
    }
    if (bad == 0 && hits > 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << bad << " of " << c.size() << " lanes differ (" << hits << " hits)";
}

TYPED_TEST(PacketTriangle, MoellerDeferredUVEqualsImmediate) {
    constexpr int K = TypeParam::value;
    Cases c;
    packet_chunk(0, c);
    EXPECT_TRUE(deferred_matches_immediate<K>(c)) << "random rays";
    EXPECT_TRUE(deferred_matches_immediate<K>(adversarial_cases(77))) << "adversarial rays";
}

/// Moeller's test on a triangle's record (accel/prims/triangle_edges.h: the
/// edges and normal computed once, read by the octree's and the grids'
/// leaves) gives the test on its vertices bit for bit: K rays against the
/// record of their packet's first triangle, against width 1 on the vertices.
template <int K>
::testing::AssertionResult record_matches_vertices(const Cases& c) {
    using F = vfloat<K>;
    std::size_t bad = 0, hits = 0;
    std::string first;
    for (std::size_t i = 0; i + K <= c.size(); i += K) {
        const Tri tri = c.tri(i);
        const auto e = triangle_detail::moeller_edges(tri.p0, tri.p1, tri.p2);
        const TriangleEdgeRecord record{tri.p0, e.e1n, e.e2, e.ng};
        auto L = [&](int field) { return load_lanes<F>(&c.f[field][i]); };
        const Vec3<F> o{L(Cases::OX), L(Cases::OY), L(Cases::OZ)}, d{L(Cases::DX), L(Cases::DY), L(Cases::DZ)};
        F t = F(0.0f), u = F(0.0f), v = F(0.0f);
        const std::uint32_t bits = mask_bits(
            intersect_triangle_record<F>(record, mask_of<F>(true), o, d, L(Cases::TN), L(Cases::TF), t, u, v));
        for (int l = 0; l < K; ++l) {
            const TestRay r = c.ray(i + std::size_t(l));
            float t1 = 0, u1 = 0, v1 = 0;
            const bool want = intersect_triangle_moeller<float>(true, r.org, r.dir, r.tnear, r.tfar, tri.p0, tri.p1,
                                                                tri.p2, t1, u1, v1);
            const bool got = (bits >> l) & 1u;
            hits += want;
            if (want == got && (!want || (same_bits(t1, lane(t, l)) && same_bits(u1, lane(u, l)) &&
                                          same_bits(v1, lane(v, l)))))
                continue;
            if (++bad == 1) first = "\n  " + str(r, tri);
        }
    }
    if (bad == 0 && hits > 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << bad << " of " << c.size() << " lanes differ (" << hits << " hits)"
                                         << first;
}

TYPED_TEST(PacketTriangle, MoellerRecordEqualsVertices) {
    constexpr int K = TypeParam::value;
    Cases c;
    for (std::size_t k = 0; k < 4; ++k) {
        packet_chunk(k, c);
        ASSERT_TRUE(record_matches_vertices<K>(c)) << "random rays, chunk " << k;
    }
    EXPECT_TRUE(record_matches_vertices<K>(adversarial_cases(77))) << "adversarial rays";
    if constexpr (K > 1) EXPECT_TRUE(record_matches_vertices<1>(adversarial_cases(78))) << "width 1";
}

/// A NaN anywhere in the Moeller test, or products that overflow, make a
/// miss at every width (a change of the edge compares, such as folding them
/// into one compare of the least margin, has to keep that).
TYPED_TEST(PacketTriangle, MoellerNonFiniteQuantitiesMiss) {
    constexpr int K = TypeParam::value;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Tri unit{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
    const float h = 1e30f;
    const Tri huge{{-h, -h, 0}, {h, -h, 0}, {0, h, 0}};  // edge products overflow: U, V, det are inf or NaN
    // In the plane x = 0, around the origin, which the ray below reaches at
    // t = 1 with det = T = -4; but d x (p0 - o) is inf - inf in x, so U and
    // V alone are NaN (width 16 folds the tests of U and V into one vmin,
    // which may drop a NaN: the compare of U + V must catch it).
    const Tri upright{{0, -1, -1}, {0, 1, -1}, {0, 0, 1}};
    const float g = 2e38f;
    Cases c;
    for (std::size_t i = 0; i < 5 * std::size_t(K); ++i) {
        const float x = 0.1f * float(i % 5) - 0.2f;
        switch (i % 5) {
            case 0: c.add({{x, 0.0f, -1.0f}, {nan, 0.0f, 1.0f}}, unit); break;
            case 1: c.add({{x, 0.0f, -1.0f}, {0.0f, nan, 1.0f}}, unit); break;
            case 2: c.add({{nan, 0.0f, -1.0f}, {0.0f, 0.0f, 1.0f}}, unit); break;
            case 3: c.add({{x, 0.0f, -1.0f}, {0.0f, 0.0f, 1.0f}}, huge); break;
            default: c.add({{-1.0f, -g, -g}, {1.0f, g, g}}, upright); break;
        }
    }
    const Answers got = run_lanes<K>(TriangleMethod::Moeller, c);
    for (std::size_t i = 0; i < c.size(); ++i) EXPECT_EQ(got.hit[i], 0) << "pair " << i << ": " << str(c.ray(i), c.tri(i));
    // The same rays with finite values hit: the misses above come from the non-finite quantities.
    Cases finite;
    for (std::size_t i = 0; i < 2 * std::size_t(K); ++i) {
        if (i % 2 == 0) finite.add({{0.0f, 0.0f, -1.0f}, {0.0f, 0.0f, 1.0f}}, unit);
        else finite.add({{-1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}}, upright);
    }
    const Answers ok = run_lanes<K>(TriangleMethod::Moeller, finite);
    for (std::size_t i = 0; i < finite.size(); ++i) EXPECT_EQ(ok.hit[i], 1) << "pair " << i;
}

// ---- Closed meshes: watertightness -------------------------------------------------

/// Octahedron with vertices +-1 on the axes around `c`, consistently wound.
std::vector<Tri> octahedron(const Vec3f& c) {
    std::vector<Tri> t;
    for (int sx : {-1, 1})
        for (int sy : {-1, 1})
            for (int sz : {-1, 1}) {
                const Vec3f a = c + Vec3f{float(sx), 0, 0}, b = c + Vec3f{0, float(sy), 0},
                            d = c + Vec3f{0, 0, float(sz)};
                t.push_back(sx * sy * sz > 0 ? Tri{a, b, d} : Tri{a, d, b});
            }
    return t;
}

/// Icosahedron subdivided `levels` times, vertices on the sphere of radius r
/// around c; shared vertices are the same floats in every triangle.
std::vector<Tri> icosphere(int levels, float r, const Vec3f& c, std::vector<Vec3f>& verts,
                           std::vector<std::array<int, 3>>& faces) {
    const float p = (1.0f + std::sqrt(5.0f)) / 2.0f;
    std::vector<Vec3d> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                            {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
    faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
             {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int l = 0; l < levels; ++l) {
        std::vector<std::array<int, 3>> next;
        std::vector<std::pair<std::pair<int, int>, int>> mid;
        auto middle = [&](int a, int b) {
            const auto key = std::make_pair(std::min(a, b), std::max(a, b));
            for (const auto& [k, i] : mid)
                if (k == key) return i;
            v.push_back((v[std::size_t(a)] + v[std::size_t(b)]) * 0.5);
            mid.push_back({key, int(v.size() - 1)});
            return int(v.size() - 1);
        };
        for (const auto& f : faces) {
            const int a = middle(f[0], f[1]), b = middle(f[1], f[2]), d = middle(f[2], f[0]);
            next.push_back({f[0], a, d});
            next.push_back({f[1], b, a});
            next.push_back({f[2], d, b});
            next.push_back({a, b, d});
        }
        faces = next;
    }
    verts.clear();
    for (const Vec3d& x : v) verts.push_back(c + Vec3f(x / std::sqrt(dot(x, x))) * r);
    std::vector<Tri> tris;
    for (const auto& f : faces) tris.push_back({verts[std::size_t(f[0])], verts[std::size_t(f[1])], verts[std::size_t(f[2])]});
    return tris;
}

/// Rays (in the first len(rays) pairs' ray fields) that hit no triangle of
/// the mesh, with K rays per packet against each triangle in turn.
template <int K>
std::size_t leaks(TriangleMethod m, const std::vector<TestRay>& rays, const std::vector<Tri>& mesh) {
    using F = vfloat<K>;
    std::size_t missed = 0;
    for (std::size_t i = 0; i < rays.size(); i += K) {
        float f[8][K];
        for (int l = 0; l < K; ++l) {
            const TestRay& r = rays[std::min(i + std::size_t(l), rays.size() - 1)];
            const float x[8] = {r.org.x, r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z, r.tnear, r.tfar};
            for (int k = 0; k < 8; ++k) f[k][l] = x[k];
        }
        const Vec3<F> o{load_lanes<F>(f[0]), load_lanes<F>(f[1]), load_lanes<F>(f[2])};
        const Vec3<F> d{load_lanes<F>(f[3]), load_lanes<F>(f[4]), load_lanes<F>(f[5])};
        std::uint32_t any_hit = 0;
        for (const Tri& t : mesh) {
            const Vec3<F> p0{F(t.p0.x), F(t.p0.y), F(t.p0.z)}, p1{F(t.p1.x), F(t.p1.y), F(t.p1.z)},
                p2{F(t.p2.x), F(t.p2.y), F(t.p2.z)};
            F tt = F(0.0f), uu = F(0.0f), vv = F(0.0f);
            any_hit |= mask_bits(intersect<F>(m, mask_of<F>(true), o, d, load_lanes<F>(f[6]), load_lanes<F>(f[7]), p0,
                                              p1, p2, tt, uu, vv));
        }
        for (int l = 0; l < K && i + std::size_t(l) < rays.size(); ++l) missed += !((any_hit >> l) & 1u);
    }
    return missed;
}

TYPED_TEST(PacketTriangle, WatertightNeverLeaksThroughSharedEdgesAndVertices) {
    constexpr int K = TypeParam::value;
    // Octahedron, exact: dyadic origins inside and outside, aimed at dyadic
    // points of its edges (a + s (b - a), s = k/16) and at its vertices, so
    // that d = target - origin is exact and the ray passes exactly through
    // the shared edge or vertex.
    struct Mesh {
        const char* what;
        std::vector<Tri> tris;
        std::vector<TestRay> rays;
    };
    std::vector<Mesh> meshes;
    for (const Vec3f c : {Vec3f{0, 0, 0}, Vec3f{0.5f, -0.25f, 0.125f}}) {
        Mesh m{"octahedron", octahedron(c), {}};
        const Vec3f v[6] = {c + Vec3f{1, 0, 0}, c + Vec3f{-1, 0, 0}, c + Vec3f{0, 1, 0},
                            c + Vec3f{0, -1, 0}, c + Vec3f{0, 0, 1}, c + Vec3f{0, 0, -1}};
        std::vector<Vec3f> origins;
        for (int i = -2; i <= 2; ++i)
            for (int j = -2; j <= 2; ++j) origins.push_back(c + Vec3f{float(i) / 8, float(j) / 16, float(i * j) / 32});
        for (const Vec3f o : {Vec3f{3, 2, 1}, Vec3f{-2, 0.5f, 2}, Vec3f{0, 0, -4}, Vec3f{1.5f, -1.5f, 0.25f}})
            origins.push_back(c + o);
        for (int a = 0; a < 6; ++a)
            for (int b = 0; b < 6; ++b) {
                if (a / 2 == b / 2) continue;  // opposite vertices share no edge
                for (int s = 0; s <= 16; ++s) {
                    const Vec3f target = v[a] + (v[b] - v[a]) * (float(s) / 16);
                    for (std::size_t oi = 0; oi < origins.size(); oi += 3 + std::size_t(s % 3)) {
                        // Only rays that cross the surface there: one touching a
                        // silhouette edge or vertex from outside has no interior
                        // to leak into, and rounding the shear may turn its
                        // touch into a near miss.
                        const Vec3f d = target - origins[oi];
                        auto inside = [&](double step) {
                            const Vec3d q = Vec3d(target) + Vec3d(d) * step - Vec3d(c);
                            return std::fabs(q.x) + std::fabs(q.y) + std::fabs(q.z) < 1.0;
                        };
                        if (inside(-1.0 / 64) == inside(1.0 / 64)) continue;
                        m.rays.push_back({origins[oi], d});
                    }
                }
            }
        meshes.push_back(m);
    }
    // Icosphere (320 triangles), near the origin and far from it: origins
    // inside, aimed at float points of shared edges (p_a + s (p_b - p_a)) and
    // at shared vertices; every such ray must leave through some triangle.
    Gen g(4242);
    for (const Vec3f c : {Vec3f{0, 0, 0}, Vec3f{1000.5f, -300.25f, 77.0f}}) {
        std::vector<Vec3f> verts;
        std::vector<std::array<int, 3>> faces;
        Mesh m{"icosphere", icosphere(2, 2.0f, c, verts, faces), {}};
        for (const auto& f : faces)
            for (int e = 0; e < 3; ++e) {
                const Vec3f a = verts[std::size_t(f[std::size_t(e)])], b = verts[std::size_t(f[std::size_t((e + 1) % 3)])];
                for (int k = 0; k < 3; ++k) {
                    const float s = k == 0 ? 0.0f : k == 1 ? 0.5f : g.uni(0.0f, 1.0f);
                    const Vec3f target = a + (b - a) * s;
                    const Vec3f o = c + g.unit() * g.uni(0.0f, 0.6f);
                    m.rays.push_back({o, (target - o) * g.pow2(-2.0f, 2.0f)});
                }
            }
        meshes.push_back(m);
    }
    for (const Mesh& mesh : meshes) {
        for (TriangleMethod m : kMethods) {
            const std::size_t n = leaks<K>(m, mesh.rays, mesh.tris);
            if (m == TriangleMethod::Watertight) {
                EXPECT_EQ(n, 0u) << mesh.what << ": " << n << " of " << mesh.rays.size() << " rays passed through";
            } else if (K == 1) {
                std::printf("  [%s] %s: %zu of %zu rays through shared edges/vertices leak (%.3f%%)\n", name(m),
                            mesh.what, n, mesh.rays.size(), 100.0 * double(n) / double(mesh.rays.size()));
            }
        }
    }
}

// ---- Width-1 float against the double instantiation -----------------------------

/// The double-precision picture of one ray-triangle pair, following each
/// variant's own arithmetic: the plane parameter t, the barycentrics b of
/// the plane point (weights of p0, p1, p2), the determinant, and first-order
/// running-error scales (Higham, "Accuracy and Stability of Numerical
/// Algorithms", ch. 3): the float kernel's value of x is within
/// kBound * eps * e_x of x. The edge tests decide on b_i (or on the sign of
/// the quantity b_i stands for), so a float/double disagreement is explained
/// when some |b_i| <= kBound * eps * eb_i (the plane point is within rounding
/// of an edge), |det| <= kBound * eps * edet, or t is within kBound * eps * et
/// of tnear or tfar.
struct Analysis {
    double t = 0, det = 0, b[3] = {}, et = 0, edet = 0, eb[3] = {};
    double edge_distance = 0;  // of the ray to the nearest edge, / (eps * coordinate size)
};

/// Error bound constant: the deepest chain of roundings in the kernels
/// (difference, cross product, dot product, division, product) is about 8,
/// gamma_8 ~ 8 eps.
constexpr double kBound = 8.0;

Vec3d abs3(const Vec3d& a) { return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}; }
/// Bound on the magnitudes of the terms of a x b.
Vec3d abs_cross(const Vec3d& a, const Vec3d& b) {
    const Vec3d x = abs3(a), y = abs3(b);
    return {x.y * y.z + x.z * y.y, x.z * y.x + x.x * y.z, x.x * y.y + x.y * y.x};
}

/// Least distance between the line o + t d and the segment [a, b].
double line_segment_distance(const Vec3d& o, const Vec3d& d, const Vec3d& a, const Vec3d& b) {
    const Vec3d e = b - a, r = a - o;
    const double dd = dot(d, d), ee = dot(e, e), de = dot(d, e), dr = dot(d, r), er = dot(e, r);
    auto at = [&](double s) {  // distance from a + s e to the line
        const Vec3d q = r + e * s;
        const Vec3d x = q - d * (dot(d, q) / dd);
        return std::sqrt(dot(x, x));
    };
    double best = std::min(at(0.0), at(1.0));
    const double den = dd * ee - de * de;  // segment parameter of the closest points of the two lines
    if (ee > 0 && den > 0) {
        const double s = (de * dr - dd * er) / den;
        if (s > 0 && s < 1) best = std::min(best, at(s));
    }
    return best;
}

Analysis analyse(TriangleMethod m, const TestRay& r, const Tri& tri) {
    const Vec3d o(r.org), d(r.dir), p0(tri.p0), p1(tri.p1), p2(tri.p2);
    Analysis a;
    const Vec3d e1 = p1 - p0, e2 = p2 - p0, n = cross(e1, e2), na = abs_cross(e1, e2), w = p0 - o;
    if (m == TriangleMethod::Watertight) {
        const Vec3d ad = abs3(d);
        const int kz = ad.x >= ad.y && ad.x >= ad.z ? 0 : ad.y >= ad.z ? 1 : 2;
        const int kx = (kz + 1) % 3, ky = (kz + 2) % 3;
        const double sx = d[kx] / d[kz], sy = d[ky] / d[kz], sz = 1.0 / d[kz];
        const Vec3d P[3] = {p0 - o, p1 - o, p2 - o};
        double x[3], y[3], z[3], xa[3], ya[3];
        for (int i = 0; i < 3; ++i) {
            x[i] = P[i][kx] - sx * P[i][kz], y[i] = P[i][ky] - sy * P[i][kz], z[i] = sz * P[i][kz];
            xa[i] = std::fabs(P[i][kx]) + std::fabs(sx * P[i][kz]), ya[i] = std::fabs(P[i][ky]) + std::fabs(sy * P[i][kz]);
        }
        double E[3], EA[3];  // U, V, W: weights of p0, p1, p2
        for (int i = 0; i < 3; ++i) {
            const int j = (i + 1) % 3, k = (i + 2) % 3;  // edge j -> k
            E[i] = x[k] * y[j] - y[k] * x[j];
            EA[i] = xa[k] * ya[j] + ya[k] * xa[j];
        }
        a.det = E[0] + E[1] + E[2];
        a.edet = EA[0] + EA[1] + EA[2];
        const double T = E[0] * z[0] + E[1] * z[1] + E[2] * z[2];
        const double TA = EA[0] * std::fabs(z[0]) + EA[1] * std::fabs(z[1]) + EA[2] * std::fabs(z[2]);
        a.t = T / a.det;
        a.et = (TA + std::fabs(a.t) * a.edet) / std::fabs(a.det) + std::fabs(a.t);
        for (int i = 0; i < 3; ++i) a.b[i] = E[i] / a.det, a.eb[i] = EA[i] / std::fabs(a.det);
    } else if (m == TriangleMethod::Moeller) {
        // The kernel's grouping: det = d . ng, U = e2 . s, V = -e1 . s,
        // T = w . ng with ng = e2 x e1, s = d x w.
        const Vec3d s = cross(d, w), sa = abs_cross(d, w);
        a.det = -dot(d, n);
        a.edet = dot(abs3(d), na);
        const double U = dot(e2, s), V = -dot(e1, s), T = -dot(w, n);
        const double UA = dot(abs3(e2), sa), VA = dot(abs3(e1), sa), TA = dot(abs3(w), na);
        a.t = T / a.det;
        a.et = (TA + std::fabs(a.t) * a.edet) / std::fabs(a.det) + std::fabs(a.t);
        a.b[1] = U / a.det, a.b[2] = V / a.det, a.b[0] = (a.det - U - V) / a.det;
        a.eb[1] = UA / std::fabs(a.det), a.eb[2] = VA / std::fabs(a.det);
        a.eb[0] = (UA + VA + a.edet) / std::fabs(a.det);
    } else {
        a.det = dot(n, d);
        a.edet = dot(na, abs3(d));
        const double T = dot(n, w), TA = dot(na, abs3(w));
        a.t = T / a.det;
        a.et = (TA + std::fabs(a.t) * a.edet) / std::fabs(a.det) + std::fabs(a.t);
        // U = q . n1, V = q . n2 with q = d t - w, n1 = e2 x n, n2 = n x e1,
        // tested against |n|^2: u = U / |n|^2, v = V / |n|^2.
        const double nn = dot(n, n);
        const Vec3d n1 = cross(e2, n), n2 = cross(n, e1);
        const Vec3d q = d * a.t - w;
        const Vec3d qa = abs3(d) * (std::fabs(a.t) + a.et) + abs3(w);
        const Vec3d n1a = abs_cross(e2, na), n2a = abs_cross(na, e1);  // n1, n2 from the rounded n
        a.b[1] = dot(q, n1) / nn, a.b[2] = dot(q, n2) / nn, a.b[0] = 1.0 - a.b[1] - a.b[2];
        a.eb[1] = (dot(qa, abs3(n1)) + dot(abs3(q), n1a)) / nn;
        a.eb[2] = (dot(qa, abs3(n2)) + dot(abs3(q), n2a)) / nn;
        a.eb[0] = a.eb[1] + a.eb[2] + 2.0 * dot(na, abs3(n)) / nn;
    }
    // How close the ray passes to the triangle's boundary: the least distance
    // between the ray's line and an edge segment, in units of eps times the
    // size of the coordinates involved.
    const Vec3d pts[3] = {p0, p1, p2};
    double size = std::max({std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)});
    for (const Vec3d& p : pts) size = std::max({size, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    a.edge_distance = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i)
        a.edge_distance = std::min(a.edge_distance, line_segment_distance(o, d, pts[i], pts[(i + 1) % 3]) / (kEpsF * size));
    return a;
}

enum class Why { NearEdge, NearParallel, NearInterval, Unexplained };

Why explain(const Analysis& a, const TestRay& r) {
    const double tol = kBound * kEpsF;
    for (int i = 0; i < 3; ++i)
        if (std::fabs(a.b[i]) <= tol * a.eb[i]) return Why::NearEdge;
    if (!(std::fabs(a.det) > tol * a.edet)) return Why::NearParallel;
    if (std::fabs(a.t - double(r.tnear)) <= tol * a.et || std::fabs(a.t - double(r.tfar)) <= tol * a.et)
        return Why::NearInterval;
    return Why::Unexplained;
}

struct ReferenceStats {
    std::size_t pairs = 0, both_hit = 0, float_only = 0, double_only = 0;
    std::size_t why[4] = {};
    double worst_t = 0;          // max |t_f - t_d| / (eps * et) over hits both agree on
    double worst_ulps = 0;       // max |t_f - t_d| in ulps of t_d
    double worst_ulps_cond = 0;  // the same over well-conditioned hits (et <= 4 |t|)
    double worst_edge = 0;       // max edge_distance over disagreements not at tnear/tfar
    std::string first;
};

double ulps_of(double x) {
    const float f = float(std::fabs(x));
    return double(std::nextafter(f, kInf) - f);
}

void compare_with_double(TriangleMethod m, const Cases& c, ReferenceStats& s) {
    const Answers fl = run_lanes<1>(m, c);
    for (std::size_t i = 0; i < c.size(); ++i) {
        const TestRay r = c.ray(i);
        const Tri tri = c.tri(i);
        double t = 0, u = 0, v = 0;
        const bool hd = intersect<double>(m, true, Vec3d(r.org), Vec3d(r.dir), double(r.tnear), double(r.tfar),
                                          Vec3d(tri.p0), Vec3d(tri.p1), Vec3d(tri.p2), t, u, v);
        const bool hf = fl.hit[i] != 0;
        ++s.pairs;
        if (!hf && !hd) continue;
        const Analysis a = analyse(m, r, tri);
        if (hf && hd) {
            ++s.both_hit;
            const double err = std::fabs(double(fl.t[i]) - t);
            const double rel = err / (kEpsF * a.et);
            s.worst_t = std::max(s.worst_t, rel);
            const double ulps = err / ulps_of(t);
            if (t != 0) s.worst_ulps = std::max(s.worst_ulps, ulps);
            if (t != 0 && a.et <= 4 * std::fabs(t)) s.worst_ulps_cond = std::max(s.worst_ulps_cond, ulps);
            if (rel > kBound && s.first.size() < 2000) {
                char b[160];
                std::snprintf(b, sizeof b, "\n  t float %a double %a, bound %g: ", double(fl.t[i]), t,
                              kBound * kEpsF * a.et);
                s.first += b + str(r, tri);
            }
            continue;
        }
        (hf ? s.float_only : s.double_only)++;
        const Why why = explain(a, r);
        ++s.why[int(why)];
        if (why != Why::NearInterval) s.worst_edge = std::max(s.worst_edge, a.edge_distance);
        if (why == Why::Unexplained && s.first.size() < 2000) {
            char b[200];
            std::snprintf(b, sizeof b, "\n  unexplained %s: b = %g %g %g (tol %g %g %g), det %g (%g): ",
                          hf ? "float-only hit" : "double-only hit", a.b[0], a.b[1], a.b[2],
                          kBound * kEpsF * a.eb[0], kBound * kEpsF * a.eb[1], kBound * kEpsF * a.eb[2], a.det,
                          a.edet);
            s.first += b + str(r, tri);
        }
    }
}

void print(const char* what, TriangleMethod m, const ReferenceStats& s) {
    std::printf(
        "  [%s] %s: %zu pairs, %zu hits agree (t error <= %.2f eps*e_t, <= %.1f ulps, %.1f ulps when e_t <= 4|t|); "
        "%zu float-only and %zu double-only hits: %zu near an edge, %zu "
        "near-parallel (the ray within %.1f eps * size of an edge), %zu at tnear/tfar\n",
        name(m), what, s.pairs, s.both_hit, s.worst_t, s.worst_ulps, s.worst_ulps_cond, s.float_only, s.double_only,
        s.why[0], s.why[1], s.worst_edge, s.why[2]);
}

TEST(PacketTriangleReference, RandomRaysAgreeWithDoubleWithinRounding) {
    Cases c;
    for (TriangleMethod m : kMethods) {
        ReferenceStats s;
        for (std::size_t k = 0; k < kRandomRays / kChunk; ++k) {
            packet_chunk(k, c);
            compare_with_double(m, c, s);
        }
        print("random", m, s);
        EXPECT_LE(s.worst_t, kBound) << name(m) << s.first;
        // On random rays every difference is within rounding of an edge (the
        // plane point, or for nearly parallel rays the determinant), never at
        // tnear/tfar, and the ray passes within a few eps of an edge.
        EXPECT_EQ(s.why[int(Why::NearEdge)] + s.why[int(Why::NearParallel)], s.float_only + s.double_only)
            << name(m) << s.first;
        EXPECT_LE(s.worst_edge, 16.0) << name(m);
        // 8 eps e_t <= 32 eps |t| <= 64 ulps of t where e_t <= 4 |t|.
        EXPECT_LE(s.worst_ulps_cond, 64.0) << name(m);
        EXPECT_LT(s.float_only + s.double_only, s.pairs / 10000) << name(m);
    }
}

TEST(PacketTriangleReference, AdversarialRaysAgreeWithDoubleWithinRounding) {
    const Cases c = adversarial_cases(77);
    for (TriangleMethod m : kMethods) {
        ReferenceStats s;
        compare_with_double(m, c, s);
        print("adversarial", m, s);
        EXPECT_LE(s.worst_t, kBound) << name(m) << s.first;
        EXPECT_EQ(s.why[int(Why::Unexplained)], 0u) << name(m) << s.first;
    }
}

}  // namespace
}  // namespace raypack
