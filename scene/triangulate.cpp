#include "scene/triangulate.h"

#include <cmath>
#include <cstdlib>

namespace raypack {

namespace {

struct Point2 {
    double x, y;
    friend bool operator==(const Point2&, const Point2&) = default;
};

/// Twice the signed area of (a, b, c): > 0 for a left turn (counter-clockwise).
double orient(const Point2& a, const Point2& b, const Point2& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// Newell's normal (twice the vector area), relative to the first vertex so
/// that a polygon far from the origin keeps its precision.
Vec3d newell_normal(std::span<const Vec3f> v) {
    const Vec3d o(v[0]);
    Vec3d n;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const Vec3d a = Vec3d(v[i]) - o;
        const Vec3d b = Vec3d(v[i + 1 == v.size() ? 0 : i + 1]) - o;
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    return n;
}

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

void fan(std::uint32_t n, Triangles& out) {
    for (std::uint32_t i = 1; i + 1 < n; ++i) out.push_back({0, i, i + 1});
}

bool is_convex(const std::vector<Point2>& p) {
    const std::size_t n = p.size();
    for (std::size_t i = 0; i < n; ++i)
        if (orient(p[i == 0 ? n - 1 : i - 1], p[i], p[i + 1 == n ? 0 : i + 1]) < 0) return false;
    // All left turns is not enough: a pentagram turns left everywhere. The fan
    // triangles must not fold over either.
    for (std::size_t i = 1; i + 1 < n; ++i)
        if (orient(p[0], p[i], p[i + 1]) < 0) return false;
    return true;
}

/// Ear clipping (Meisters 1975, "Polygons have ears"; the procedure follows
/// Eberly, "Triangulation by Ear Clipping", Geometric Tools 2002) on a
/// counter-clockwise loop. A convex corner is an ear when no reflex or flat
/// vertex lies in or on its triangle; only those can block it in a simple
/// polygon, so they are kept in a list (Eberly's reflex list): clipping an
/// ear only ever turns a neighbour convex, never reflex. Flat corners
/// (collinear or repeated vertices) are cut off as zero-area triangles,
/// which leaves the remaining region unchanged.
///
/// The walk goes round the loop in passes: after clipping a corner it skips
/// the new neighbour and tries the corner after it, so a pass over a convex
/// stretch clips every other corner and the next pass works on half as many,
/// with triangles twice as wide. Looking at the neighbour first instead (as
/// Eberly does) clips a convex stretch as a fan from one vertex: slivers as
/// long as the polygon, all overlapping near their apex, whose boxes a BVH
/// cannot separate. gears' 144-gons (a toothed disc) became 70 such slivers
/// each; in passes their triangles' boxes cover 3.3 times the polygon's area
/// instead of 30 times, and a gears render is 1.2x faster (docs/renderer.md).
void ear_clip(const std::vector<Point2>& p, Triangles& out) {
    const auto n = std::uint32_t(p.size());
    std::vector<std::uint32_t> prev(n), next(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        prev[i] = i == 0 ? n - 1 : i - 1;
        next[i] = i + 1 == n ? 0 : i + 1;
    }
    auto corner = [&](std::uint32_t i) { return orient(p[prev[i]], p[i], p[next[i]]); };
    // The vertices whose corner is not convex (reflex or flat), and where
    // each sits in that list (or -1).
    std::vector<std::uint32_t> blockers;
    std::vector<std::int32_t> slot(n, -1);
    auto update = [&](std::uint32_t i) {
        const bool blocks = !(corner(i) > 0);
        if (blocks && slot[i] < 0) {
            slot[i] = std::int32_t(blockers.size());
            blockers.push_back(i);
        } else if (!blocks && slot[i] >= 0) {
            const std::uint32_t last = blockers.back();
            blockers[std::size_t(slot[i])] = last;
            slot[last] = slot[i];
            blockers.pop_back();
            slot[i] = -1;
        }
    };
    for (std::uint32_t i = 0; i < n; ++i) update(i);
    auto is_ear = [&](std::uint32_t i) {
        const std::uint32_t a = prev[i], c = next[i];
        if (!(corner(i) > 0)) return false;
        for (const std::uint32_t j : blockers) {
            if (j == a || j == c) continue;  // i itself is convex: not listed
            const Point2& q = p[j];
            if (q == p[a] || q == p[i] || q == p[c]) continue;  // a repeated vertex touches, it does not block
            if (orient(p[a], p[i], q) >= 0 && orient(p[i], p[c], q) >= 0 && orient(p[c], p[a], q) >= 0)
                return false;
        }
        return true;
    };

    std::uint32_t remaining = n, i = 0, misses = 0;
    while (remaining > 3) {
        if (corner(i) == 0 || is_ear(i)) {
            out.push_back({prev[i], i, next[i]});
            next[prev[i]] = next[i];
            prev[next[i]] = prev[i];
            if (slot[i] >= 0) {  // a flat corner leaves the list
                const std::uint32_t last = blockers.back();
                blockers[std::size_t(slot[i])] = last;
                slot[last] = slot[i];
                blockers.pop_back();
                slot[i] = -1;
            }
            update(prev[i]);
            update(next[i]);
            i = next[next[i]];  // skip the new neighbour: the next pass comes back to it
            --remaining;
            misses = 0;
        } else if (++misses > remaining) {
            // A full lap without an ear: the loop is not simple (self-intersecting
            // or not planar enough). Finish with a fan of what is left.
            break;
        } else {
            i = next[i];
        }
    }
    for (std::uint32_t j = next[i]; next[j] != i; j = next[j]) out.push_back({i, j, next[j]});
}

}  // namespace

std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const Vec3f> verts) {
    Triangles out;
    const std::size_t n = verts.size();
    if (n < 3) return out;
    out.reserve(n - 2);
    if (n == 3) {
        out.push_back({0, 1, 2});
        return out;
    }

    // Project onto the plane of the normal's dominant axis, keeping the
    // projection counter-clockwise so that "convex" means "left turn".
    const Vec3d normal = newell_normal(verts);
    const double ax[3] = {std::abs(normal.x), std::abs(normal.y), std::abs(normal.z)};
    const int k = ax[0] >= ax[1] ? (ax[0] >= ax[2] ? 0 : 2) : (ax[1] >= ax[2] ? 1 : 2);
    if (!(ax[k] > 0) || !std::isfinite(ax[k])) {
        // Zero vector area (all collinear, or a figure eight that cancels): no
        // plane to work in. The fan's triangles are as good as any.
        fan(std::uint32_t(n), out);
        return out;
    }
    const int u = (k + 1) % 3, v = (k + 2) % 3;
    const double flip = normal[k] > 0 ? 1.0 : -1.0;
    std::vector<Point2> p(n);
    const Vec3d o(verts[0]);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3d d = Vec3d(verts[i]) - o;
        p[i] = {d[u], flip * d[v]};
    }

    // Fans of quadrilaterals are as compact as any cut of them; larger convex
    // polygons are clipped in passes too (a fan of them is slivers).
    if (n == 4 && is_convex(p))
        fan(std::uint32_t(n), out);
    else
        ear_clip(p, out);
    return out;
}

}  // namespace raypack
