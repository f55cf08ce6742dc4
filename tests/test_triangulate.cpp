// Polygon triangulation: counts, winding, and that the triangles tile the
// polygon exactly (areas add up, none is inverted, none lies outside).
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "scene/triangulate.h"

namespace {

using raypack::Vec3d;
using raypack::Vec3f;
using Tris = std::vector<std::array<std::uint32_t, 3>>;

Vec3d newell(const std::vector<Vec3f>& v) {
    Vec3d n;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const Vec3d a(v[i]), b(v[(i + 1) % v.size()]);
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    return n;
}

double polygon_area(const std::vector<Vec3f>& v) { return 0.5 * raypack::length(newell(v)); }

/// Area of triangle t, negative when it faces away from the polygon's normal.
double signed_area(const std::vector<Vec3f>& v, const std::array<std::uint32_t, 3>& t, const Vec3d& unit_normal) {
    const Vec3d a(v[t[0]]), b(v[t[1]]), c(v[t[2]]);
    return 0.5 * raypack::dot(raypack::cross(b - a, c - a), unit_normal);
}

/// Crossing-number point-in-polygon test in the plane of the dominant axis.
bool inside(const std::vector<Vec3f>& v, const Vec3d& p, const Vec3d& n) {
    const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
    const int k = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
    const int u = (k + 1) % 3, w = (k + 2) % 3;
    bool in = false;
    for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
        const double yi = v[i][w], yj = v[j][w], xi = v[i][u], xj = v[j][u];
        if ((yi > p[w]) != (yj > p[w]) && p[u] < (xj - xi) * (p[w] - yi) / (yj - yi) + xi) in = !in;
    }
    return in;
}

/// The checks every simple polygon's triangulation must pass.
void expect_tiles(const std::vector<Vec3f>& v, const Tris& tris, double rel_tol) {
    ASSERT_EQ(tris.size(), v.size() - 2);
    const Vec3d n = raypack::normalize(newell(v));
    const double area = polygon_area(v);
    double sum_abs = 0;
    for (const auto& t : tris) {
        for (std::uint32_t i : t) ASSERT_LT(i, v.size());
        const double a = signed_area(v, t, n);
        sum_abs += std::abs(a);
        EXPECT_GE(a, -rel_tol * area) << "triangle " << t[0] << "," << t[1] << "," << t[2] << " is inverted";
        if (a > 1e-6 * area) {
            const Vec3d centroid = (Vec3d(v[t[0]]) + Vec3d(v[t[1]]) + Vec3d(v[t[2]])) / 3.0;
            EXPECT_TRUE(inside(v, centroid, n)) << "triangle " << t[0] << "," << t[1] << "," << t[2] << " outside";
        }
    }
    EXPECT_NEAR(sum_abs, area, rel_tol * area);
}

/// Sum of |area| of the fan's triangles, and whether any of them is inverted.
/// The signed sum of a fan always equals the polygon's area (it is the
/// shoelace formula), so only the unsigned sum shows a fan that folds over.
std::pair<double, bool> fan_unsigned_area(const std::vector<Vec3f>& v) {
    const Vec3d n = raypack::normalize(newell(v));
    double sum = 0;
    bool inverted = false;
    for (std::uint32_t i = 1; i + 1 < v.size(); ++i) {
        const double a = signed_area(v, {0, i, i + 1}, n);
        sum += std::abs(a);
        inverted |= a < 0;
    }
    return {sum, inverted};
}

/// Rotates points about an arbitrary axis so that no coordinate plane is special.
std::vector<Vec3f> rotated(const std::vector<Vec3f>& v, Vec3d offset = {3, -2, 5}) {
    const Vec3d axis = raypack::normalize(Vec3d{0.3, -0.7, 0.65});
    const double c = std::cos(0.9), s = std::sin(0.9);
    std::vector<Vec3f> out;
    for (const Vec3f& pf : v) {
        const Vec3d p(pf);
        const Vec3d r = p * c + raypack::cross(axis, p) * s + axis * (raypack::dot(axis, p) * (1 - c));
        out.push_back(Vec3f(r + offset));
    }
    return out;
}

std::vector<Vec3f> reversed(std::vector<Vec3f> v) { return {v.rbegin(), v.rend()}; }

std::vector<Vec3f> xy(std::initializer_list<std::pair<float, float>> pts) {
    std::vector<Vec3f> v;
    for (auto [x, y] : pts) v.push_back({x, y, 0});
    return v;
}

Tris tri(const std::vector<Vec3f>& v) { return raypack::triangulate_polygon(v); }

/// Simple by construction (star-shaped about the origin), with deep spikes.
std::vector<Vec3f> star(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> r(0.15, 1.0);
    std::vector<Vec3f> v;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * std::numbers::pi * i / n;
        const double rad = i % 2 == 0 ? 1.0 : r(rng) * 0.5;
        v.push_back({float(rad * std::cos(a)), float(rad * std::sin(a)), 0});
    }
    return v;
}

/// A comb: `teeth` tall narrow teeth on a base bar, counter-clockwise.
std::vector<Vec3f> comb(int teeth) {
    std::vector<Vec3f> v{{0, 0, 0}, {float(2 * teeth), 0, 0}};
    for (int i = teeth - 1; i >= 0; --i) {
        v.push_back({float(2 * i + 1), 5, 0});
        v.push_back({float(2 * i + 0.5f), 1, 0});
        if (i > 0) v.push_back({float(2 * i), 5, 0});
    }
    v.push_back({0, 5, 0});
    return v;
}

/// A square spiral corridor: few ears at any time.
std::vector<Vec3f> spiral(int turns) {
    std::vector<Vec3f> outer, inner;
    for (int i = 0; i < 4 * turns; ++i) {
        const double a = std::numbers::pi / 2 * i;
        const double r = 1.0 + 0.5 * i;
        outer.push_back({float(r * std::cos(a)), float(r * std::sin(a)), 0});
        inner.push_back({float((r - 0.25) * std::cos(a)), float((r - 0.25) * std::sin(a)), 0});
    }
    std::vector<Vec3f> v(outer.begin(), outer.end());
    v.insert(v.end(), inner.rbegin(), inner.rend());
    return v;
}

}  // namespace

TEST(Triangulate, FewerThanThreeVerticesGiveNothing) {
    EXPECT_TRUE(tri({}).empty());
    EXPECT_TRUE(tri({{0, 0, 0}, {1, 0, 0}}).empty());
}

TEST(Triangulate, TriangleIsItself) {
    EXPECT_EQ(tri({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}), (Tris{{0, 1, 2}}));
}

TEST(Triangulate, ConvexQuadrilateralsAreFans) {
    EXPECT_EQ(tri(xy({{0, 0}, {1, 0}, {1, 1}, {0, 1}})), (Tris{{0, 1, 2}, {0, 2, 3}}));
    EXPECT_EQ(tri(reversed(xy({{0, 0}, {1, 0}, {1, 1}, {0, 1}}))), (Tris{{0, 1, 2}, {0, 2, 3}}));
}

TEST(Triangulate, LargerConvexPolygonsAreCutInPasses) {
    // The hexagon: every other corner in the first pass, then the middle.
    std::vector<Vec3f> hex;
    for (int i = 0; i < 6; ++i) hex.push_back({float(std::cos(i * 1.0472)), float(std::sin(i * 1.0472)), 0});
    const Tris expected{{5, 0, 1}, {1, 2, 3}, {3, 4, 5}, {1, 3, 5}};
    EXPECT_EQ(tri(rotated(hex)), expected);
    expect_tiles(rotated(hex), tri(rotated(hex)), 1e-6);
    // Collinear points on the edges do not make a polygon concave.
    EXPECT_EQ(tri(xy({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {0, 1}})).size(), 4u);
    expect_tiles(xy({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {0, 1}}), tri(xy({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {0, 1}})), 1e-12);
}

namespace {

/// The most triangles that share one vertex.
std::size_t max_valence(const Tris& tris, std::size_t n) {
    std::vector<std::size_t> count(n);
    for (const auto& t : tris)
        for (std::uint32_t i : t) ++count[i];
    return *std::max_element(count.begin(), count.end());
}

/// The triangles' axis-aligned boxes' summed areas in the polygon's plane,
/// over the polygon's area: what a BVH over them pays (a fan of slivers
/// from one vertex: tens of times the polygon).
double box_cover(const std::vector<Vec3f>& v, const Tris& tris) {
    const Vec3d n = raypack::normalize(newell(v));
    const Vec3d e1 = raypack::normalize(raypack::cross(std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}, n));
    const Vec3d e2 = raypack::cross(n, e1);
    double sum = 0;
    for (const auto& t : tris) {
        double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
        for (std::uint32_t i : t) {
            const double c[2] = {raypack::dot(Vec3d(v[i]), e1), raypack::dot(Vec3d(v[i]), e2)};
            for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
        }
        sum += (hi[0] - lo[0]) * (hi[1] - lo[1]);
    }
    return sum / polygon_area(v);
}

Tris fan_of(std::size_t n) {
    Tris f;
    for (std::uint32_t i = 1; i + 1 < n; ++i) f.push_back({0, i, i + 1});
    return f;
}

}  // namespace

TEST(Triangulate, ManySidedPolygonsGetCompactTrianglesNotSlivers) {
    // A regular 64-gon and a 61-gon (odd passes); gears' toothed discs are
    // the 144-gons' case below.
    for (int n : {64, 61}) {
        SCOPED_TRACE(n);
        std::vector<Vec3f> v;
        for (int i = 0; i < n; ++i)
            v.push_back({float(std::cos(2 * std::numbers::pi * i / n)), float(std::sin(2 * std::numbers::pi * i / n)), 0});
        v = rotated(v);
        const Tris t = tri(v);
        expect_tiles(v, t, 1e-5);
        // Passes: a vertex survives at most log2(n) of them, two triangles each.
        EXPECT_LE(max_valence(t, v.size()), 2 * std::size_t(std::ceil(std::log2(n))) + 1);
        EXPECT_LT(box_cover(v, t), 4.0);
        EXPECT_GT(box_cover(v, fan_of(v.size())), 8.0) << "the bound would not rule out the fan";
    }
}

TEST(Triangulate, TrianglesKeepThePolygonsWinding) {
    for (const auto& poly : {xy({{0, 0}, {1, 0}, {1, 1}, {0, 1}}), comb(3), star(40, 1)}) {
        for (const auto& v : {poly, reversed(poly), rotated(poly), rotated(reversed(poly))}) {
            const Vec3d n = newell(v);
            for (const auto& t : tri(v)) {
                const Vec3d a(v[t[0]]), b(v[t[1]]), c(v[t[2]]);
                EXPECT_GT(raypack::dot(raypack::cross(b - a, c - a), n), 0);
            }
        }
    }
}

TEST(Triangulate, ConcaveLShape) {
    // From vertex 0 the fan crosses the notch: (0,2) (2,1) (1,1) is inverted.
    const auto v = xy({{0, 2}, {0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}});
    const auto [fan_area, fan_inverted] = fan_unsigned_area(v);
    EXPECT_TRUE(fan_inverted);
    EXPECT_GT(fan_area, polygon_area(v) * 1.01);
    expect_tiles(v, tri(v), 1e-12);
    expect_tiles(rotated(v), tri(rotated(v)), 1e-6);
    expect_tiles(reversed(v), tri(reversed(v)), 1e-12);
}

TEST(Triangulate, ConcaveArrow) {
    const auto v = xy({{0, 0}, {4, 0}, {4, 4}, {2, 1}, {0, 4}});
    EXPECT_NEAR(polygon_area(v), 10.0, 1e-12);
    const auto [fan_area, fan_inverted] = fan_unsigned_area(v);
    EXPECT_TRUE(fan_inverted);
    EXPECT_GT(fan_area, polygon_area(v) * 1.01);
    const Tris t = tri(v);
    expect_tiles(v, t, 1e-12);
    for (const auto& x : t) EXPECT_NE(x, (std::array<std::uint32_t, 3>{0, 2, 3}));
}

TEST(Triangulate, CombsStarsAndSpirals) {
    for (int teeth : {1, 2, 5, 20}) {
        SCOPED_TRACE("comb " + std::to_string(teeth));
        const auto v = comb(teeth);
        expect_tiles(v, tri(v), 1e-12);
        expect_tiles(rotated(v), tri(rotated(v)), 1e-5);
        expect_tiles(reversed(v), tri(reversed(v)), 1e-12);
    }
    for (unsigned seed = 1; seed <= 20; ++seed) {
        SCOPED_TRACE("star " + std::to_string(seed));
        const auto v = star(10 + 7 * int(seed), seed);
        expect_tiles(v, tri(v), 1e-9);
        expect_tiles(rotated(v), tri(rotated(v)), 1e-5);
    }
    for (int turns : {1, 2, 5}) {
        SCOPED_TRACE("spiral " + std::to_string(turns));
        const auto v = spiral(turns);
        expect_tiles(v, tri(v), 1e-9);
        expect_tiles(rotated(reversed(v)), tri(rotated(reversed(v))), 1e-5);
    }
}

TEST(Triangulate, SubdividedStaircase) {
    // Integer coordinates with every edge cut into unit steps: exact
    // collinearity everywhere, and reflex corners on the ears' diagonals.
    for (int steps : {1, 2, 4, 9}) {
        SCOPED_TRACE("steps " + std::to_string(steps));
        std::vector<std::pair<int, int>> corners{{0, 0}};
        for (int i = 0; i < steps; ++i) {
            corners.push_back({2 * (i + 1), 2 * i});
            corners.push_back({2 * (i + 1), 2 * (i + 1)});
        }
        corners.push_back({0, 2 * steps});
        std::vector<Vec3f> v;
        for (std::size_t i = 0; i < corners.size(); ++i) {
            auto [x0, y0] = corners[i];
            auto [x1, y1] = corners[(i + 1) % corners.size()];
            const int len = std::max(std::abs(x1 - x0), std::abs(y1 - y0));
            for (int k = 0; k < len; ++k)
                v.push_back({float(x0 + (x1 - x0) * k / len), float(y0 + (y1 - y0) * k / len), 0});
        }
        expect_tiles(v, tri(v), 1e-12);
        expect_tiles(reversed(v), tri(reversed(v)), 1e-12);
        expect_tiles(rotated(v), tri(rotated(v)), 1e-5);
    }
}

TEST(Triangulate, LargeConcavePolygonIsFast) {
    const auto v = star(4000, 7);
    expect_tiles(v, tri(v), 1e-9);
}

TEST(Triangulate, CollinearAndDuplicateVertices) {
    // Concave, with points along edges and a repeated vertex.
    const auto v = xy({{0, 0}, {1, 0}, {2, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {1, 3}, {0, 3}, {0, 1.5f}});
    expect_tiles(v, tri(v), 1e-12);
    // A zero-width spike on a concave polygon.
    const auto s = xy({{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1.5f, 1}, {2.5f, 1}, {1, 1}, {1, 3}, {0, 3}});
    const Tris ts = tri(s);
    ASSERT_EQ(ts.size(), s.size() - 2);
    double sum = 0;
    const Vec3d n = raypack::normalize(newell(s));
    for (const auto& t : ts) sum += std::abs(signed_area(s, t, n));
    EXPECT_NEAR(sum, polygon_area(s), 1e-12);
}

TEST(Triangulate, DegeneratePolygonsGiveFans) {
    // All collinear: zero Newell normal; loads as its zero-area fan.
    const std::vector<Vec3f> line{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {1.5f, 1.5f, 1.5f}};
    EXPECT_EQ(tri(line), (Tris{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}}));
    const std::vector<Vec3f> point(7, Vec3f{1, 2, 3});
    EXPECT_EQ(tri(point).size(), 5u);
}

TEST(Triangulate, SelfIntersectingInputTerminatesWithNMinus2) {
    const auto bowtie = xy({{0, 0}, {1, 1}, {1, 0}, {0, 1}});
    EXPECT_EQ(tri(bowtie).size(), 2u);
    std::vector<Vec3f> pentagram;
    for (int i = 0; i < 5; ++i) {
        const double a = std::numbers::pi / 2 + 2 * std::numbers::pi * (2 * i) / 5;
        pentagram.push_back({float(std::cos(a)), float(std::sin(a)), 0});
    }
    EXPECT_EQ(tri(pentagram).size(), 3u);
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> d(-1, 1);
    for (int n : {4, 5, 10, 50, 300}) {
        std::vector<Vec3f> junk;
        for (int i = 0; i < n; ++i) junk.push_back({d(rng), d(rng), d(rng) * 0.1f});
        const Tris t = tri(junk);
        ASSERT_EQ(t.size(), std::size_t(n - 2));
        for (const auto& x : t)
            for (std::uint32_t i : x) EXPECT_LT(i, std::uint32_t(n));
    }
}

TEST(Triangulate, NonFiniteInputTerminates) {
    const std::vector<Vec3f> v{{0, 0, 0}, {1, 0, 0}, {NAN, 1, 0}, {0, 1, 0}, {0.5f, 0.5f, 0}};
    EXPECT_EQ(tri(v).size(), 3u);
}

TEST(Triangulate, GearsConcave144GonsTileExactlyAndTheFanDoesNot) {
    std::ifstream in(std::string(RAYPACK_SOURCE_DIR) + "/scenes/gears.nff");
    ASSERT_TRUE(in);
    std::vector<std::vector<Vec3f>> polys;
    for (std::string kw; in >> kw;) {
        if (kw != "p") continue;
        int n;
        in >> n;
        std::vector<Vec3f> v(n);
        for (auto& p : v) in >> p.x >> p.y >> p.z;
        if (n == 144) polys.push_back(v);
    }
    ASSERT_EQ(polys.size(), 128u);
    int fans_failing = 0;
    for (std::size_t i = 0; i < polys.size(); ++i) {
        SCOPED_TRACE("144-gon " + std::to_string(i));
        const auto& v = polys[i];
        const double area = polygon_area(v);
        const Tris t = tri(v);
        expect_tiles(v, t, 1e-5);
        // In passes: the teeth, then the disc inside them halved pass by
        // pass (clipping toward the neighbour first made 70 slivers from one
        // vertex: their boxes covered 30 times the polygon).
        EXPECT_LT(box_cover(v, t), 4.0);
        EXPECT_LE(max_valence(t, v.size()), 16u);
        // The fan: its signed areas sum to the polygon's (shoelace), but some
        // of its triangles are inverted, so the unsigned sum is too large.
        const Vec3d n = raypack::normalize(newell(v));
        double signed_sum = 0;
        for (std::uint32_t k = 1; k + 1 < v.size(); ++k) signed_sum += signed_area(v, {0, k, k + 1}, n);
        EXPECT_NEAR(signed_sum, area, 1e-5 * area);
        const auto [fan_abs, inverted] = fan_unsigned_area(v);
        if (inverted && std::abs(fan_abs - area) > 1e-3 * area) ++fans_failing;
    }
    EXPECT_EQ(fans_failing, 128) << "a fan would pass the area check, so that check proves nothing";
}
