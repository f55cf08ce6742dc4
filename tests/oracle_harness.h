#pragma once
// Helpers shared by the tests that check a structure against the brute-force
// oracle: readable ray and hit descriptions, camera, random and shadow rays,
// comparisons with the oracle's answers (Mismatches), test parameter names.
#include <gtest/gtest.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <cstdint>
#include <iomanip>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/primitive_intersector.h"
#include "kernels/aabb.h"
#include "render/camera_rays.h"
#include "scene/scene.h"
#include "tests/test_paths.h"

namespace raypack::oracle_harness {

inline std::string describe(const Rayf& r) {
    std::ostringstream os;
    os << std::hexfloat << "org (" << r.org.x << ", " << r.org.y << ", " << r.org.z << ") dir (" << r.dir.x << ", "
       << r.dir.y << ", " << r.dir.z << ") tnear " << r.tnear << " tfar " << r.tfar << std::defaultfloat << " ["
       << r.org.x << ", " << r.org.y << ", " << r.org.z << " / " << r.dir.x << ", " << r.dir.y << ", " << r.dir.z
       << "]";
    return os.str();
}

/// The same hit to the last bit: primitive, t, u and v.
inline bool same_bits(const Hitf& a, const Hitf& b) {
    const auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f); };
    return a.prim == b.prim && bits(a.t) == bits(b.t) && bits(a.u) == bits(b.u) && bits(a.v) == bits(b.v);
}

inline std::string describe(const Hitf& h) {
    if (!h.found()) return "miss";
    std::ostringstream os;
    os << "prim " << h.prim << " t " << std::setprecision(9) << h.t;
    return os.str();
}

inline Vec3f random_direction(std::mt19937& rng) {
    std::normal_distribution<float> n;
    for (;;) {
        const Vec3f d{n(rng), n(rng), n(rng)};
        if (dot(d, d) > 1e-6f) return normalize(d);
    }
}

inline Vec3f random_point(std::mt19937& rng, const Box3f& box) {
    std::uniform_real_distribution<float> u(0, 1);
    const Vec3f e = box.extent();
    return {box.lo.x + u(rng) * e.x, box.lo.y + u(rng) * e.y, box.lo.z + u(rng) * e.z};
}

inline float signed_zero(std::mt19937& rng) { return rng() % 2 ? 0.0f : -0.0f; }

inline Box3f grown(Box3f b, float f) {
    const Vec3f e = b.extent() * f;
    b.lo -= e;
    b.hi += e;
    return b;
}

/// Closest hits of `rays` through Accel::intersect_packets with `width` (1:
/// single rays), in batches of 256 on all cores.
inline std::vector<Hitf> trace_hits(const Accel& accel, const std::vector<Rayf>& rays, int width = 1) {
    std::vector<Hitf> hits(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const auto& r) {
        accel.intersect_packets(width, std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                                std::span<Hitf>(hits).subspan(r.begin(), r.size()));
    });
    return hits;
}

/// Occlusion answers of `rays` through Accel::occluded_packets, as trace_hits().
inline std::vector<std::uint8_t> trace_occlusion(const Accel& accel, const std::vector<Rayf>& rays, int width = 1) {
    std::vector<std::uint8_t> occ(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const auto& r) {
        accel.occluded_packets(width, std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                               std::span<std::uint8_t>(occ).subspan(r.begin(), r.size()));
    });
    return occ;
}

/// One ray through the centre of every pixel of a size x size image of the
/// scene's camera, row by row.
/// Closest hits that agree exactly: same hit or miss; the same primitive at
/// the bit-identical t; another primitive only at a t within 1e-5 (a shared
/// edge or vertex, where either is right). The first few that do not, described.
inline std::string hit_mismatches(const std::vector<Rayf>& rays, const std::vector<Hitf>& want,
                                  const std::vector<Hitf>& got, std::size_t& count, const char* want_name = "want",
                                  const char* got_name = "got") {
    std::string first;
    count = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        bool ok = want[i].found() == got[i].found();
        if (ok && want[i].found()) {
            ok = want[i].prim == got[i].prim
                     ? want[i].t == got[i].t
                     : std::fabs(want[i].t - got[i].t) <= 1e-5f * std::max(std::fabs(want[i].t), std::fabs(got[i].t));
        }
        if (ok) continue;
        if (++count <= 5)
            first += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    " + want_name + " " +
                     describe(want[i]) + ", " + got_name + " " + describe(got[i]);
    }
    return first;
}

/// Occlusion answers that differ, the first few described.
inline std::string occlusion_mismatches(const std::vector<Rayf>& rays, const std::vector<std::uint8_t>& want,
                                        const std::vector<std::uint8_t>& got, std::size_t& count) {
    std::string first;
    count = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (want[i] == got[i]) continue;
        if (++count <= 5)
            first += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    want " +
                     (want[i] ? "occluded" : "clear") + ", got " + (got[i] ? "occluded" : "clear");
    }
    return first;
}

/// How a structure's packets must answer against its own single rays.
enum class PacketAnswers {
    UpToTies,  ///< as hit_mismatches: another primitive only at the same t (a shared edge)
    BitForBit  ///< the same primitive, t, u and v to the bit
};

/// Closest hit and occlusion of every ray against brute force (exact, ties
/// at shared edges aside), then packets of every compiled width against the
/// structure's own single rays.
inline void expect_oracle_agreement(const Scene& scene, const Accel& accel, const std::vector<Rayf>& rays,
                                    const std::string& what, PacketAnswers packets = PacketAnswers::UpToTies) {
    const BruteForce brute(scene, KernelChoice{});
    const std::vector<Hitf> truth = trace_hits(brute, rays);
    const std::vector<Hitf> single = trace_hits(accel, rays);
    std::size_t n = 0;
    std::string s = hit_mismatches(rays, truth, single, n, "brute", "single");
    EXPECT_EQ(n, 0u) << what << ": " << n << " of " << rays.size() << " closest hits differ" << s;
    // Brute force finds a closest hit iff some primitive is hit within the
    // ray's [tnear, tfar], which is its occlusion answer.
    std::vector<std::uint8_t> occluded(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = truth[i].found() ? 1 : 0;
    s = occlusion_mismatches(rays, occluded, trace_occlusion(accel, rays), n);
    EXPECT_EQ(n, 0u) << what << ": " << n << " of " << rays.size() << " occlusion answers differ" << s;
    for (int width : {4, 8, 16}) {
        if (!accel.supports_packet(width)) continue;
        const std::vector<Hitf> got = trace_hits(accel, rays, width);
        if (packets == PacketAnswers::UpToTies) {
            s = hit_mismatches(rays, single, got, n, "single", "packet");
        } else {
            s.clear(), n = 0;
            auto bits = [](float x) { return std::bit_cast<std::uint32_t>(x); };
            for (std::size_t i = 0; i < rays.size(); ++i) {
                const Hitf &w = single[i], &g = got[i];
                const bool same = g.prim == w.prim && bits(g.t) == bits(w.t) &&
                                  (!w.found() || (bits(g.u) == bits(w.u) && bits(g.v) == bits(w.v)));
                if (!same && ++n <= 3)
                    s += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    single " + describe(w) +
                         ", packet " + describe(g);
            }
        }
        EXPECT_EQ(n, 0u) << what << " width " << width << ": " << n << " of " << rays.size()
                         << " packet hits differ from single rays" << s;
        s = occlusion_mismatches(rays, occluded, trace_occlusion(accel, rays, width), n);
        EXPECT_EQ(n, 0u) << what << " width " << width << ": " << n << " of " << rays.size()
                         << " packet occlusion answers differ" << s;
    }
}

/// random_rays() draws origins in the scene box grown by this fraction per
/// side, so that some start outside the structure.
inline constexpr float kOriginGrowth = 0.2f;

/// Every scenes/*.nff plus the bunny, found on disk so that new scenes join in.
inline std::vector<std::string> shared_scene_files() {
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::directory_iterator(std::string(RAYPACK_SOURCE_DIR) + "/scenes"))
        if (e.path().extension() == ".nff") files.push_back(e.path().filename().string());
    std::sort(files.begin(), files.end());
    files.push_back("bunny.obj");
    return files;
}

inline std::vector<Rayf> camera_rays(const Scene& scene, int size) {
    const CameraFrame f = make_camera_frame(scene.camera, size, size);
    std::vector<Rayf> rays;
    rays.reserve(std::size_t(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) rays.push_back(camera_ray(f, float(x) + 0.5f, float(y) + 0.5f));
    return rays;
}

/// n rays with random origins in `origins`, random directions, and every
/// second one (odd index) a tfar drawn uniformly from [0, max_tfar).
inline std::vector<Rayf> random_rays_in(std::mt19937& rng, const Box3f& origins, float max_tfar, int n) {
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<Rayf> rays(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        rays[i].org = random_point(rng, origins);
        rays[i].dir = random_direction(rng);
        if (i % 2) rays[i].tfar = u(rng) * max_tfar;
    }
    return rays;
}

/// random_rays_in() with origins in the scene box grown by `grow` of its
/// extent on every side, and finite tfar up to the (ungrown) box's diagonal.
inline std::vector<Rayf> random_rays(const Scene& scene, std::mt19937& rng, int n, float grow = 0.0f) {
    const Box3f box = scene_bounds(scene);
    return random_rays_in(rng, grow == 0.0f ? box : grown(box, grow), length(box.extent()), n);
}

/// A unit direction along `axis` with sign `sign`, the other components +-0.
inline Vec3f axis_direction(std::mt19937& rng, int axis, float sign) {
    Vec3f d{signed_zero(rng), signed_zero(rng), signed_zero(rng)};
    d[axis] = sign;
    return d;
}

// Rays from a structure's own planes: `plane(axis)` returns one of its
// planes across `axis` (drawing from the caller's rng), `corner()` a point
// whose three coordinates are such planes.

/// Appends n axis-parallel rays along lines where two planes meet (a
/// corner() with the coordinate along axis i % 3 moved outside `box` by a
/// tenth of its diagonal), pointing into the box.
template <class Corner>
void append_edge_rays(std::vector<Rayf>& rays, std::mt19937& rng, const Box3f& box, Corner&& corner, int n) {
    const float diag = length(box.extent());
    for (int i = 0; i < n; ++i) {
        const int a = i % 3;
        const float sign = (i / 3) % 2 ? 1.0f : -1.0f;
        Rayf r;
        r.org = corner();
        r.org[a] = sign > 0 ? box.lo[a] - 0.1f * diag : box.hi[a] + 0.1f * diag;
        r.dir = axis_direction(rng, a, sign);
        rays.push_back(r);
    }
}

/// Appends n rays inside a plane across axis i % 3 (that direction
/// component +-0) from random points of `box`.
template <class Plane>
void append_in_plane_rays(std::vector<Rayf>& rays, std::mt19937& rng, const Box3f& box, Plane&& plane, int n) {
    for (int i = 0; i < n; ++i) {
        const int a = i % 3;
        Rayf r;
        r.org = random_point(rng, box);
        r.org[a] = plane(a);
        r.dir = random_direction(rng);
        r.dir[a] = signed_zero(rng);
        rays.push_back(r);
    }
}

/// Appends n axis-parallel rays (axis i % 3, both ways) from random points of
/// `box` grown by a tenth, every other one ending at a finite tfar.
inline void append_axis_parallel_rays(std::vector<Rayf>& rays, std::mt19937& rng, const Box3f& box, int n) {
    const float diag = length(box.extent());
    std::uniform_real_distribution<float> u(0, 1);
    for (int i = 0; i < n; ++i) {
        Rayf r;
        r.org = random_point(rng, grown(box, 0.1f));
        r.dir = axis_direction(rng, i % 3, (i / 3) % 2 ? 1.0f : -1.0f);
        if (i % 2) r.tfar = u(rng) * diag;
        rays.push_back(r);
    }
}

/// Appends n rays from random points of `box` in random directions, every
/// other one from tnear > 0 (the walk begins midway), every third ending at
/// a finite tfar.
inline void append_inside_rays(std::vector<Rayf>& rays, std::mt19937& rng, const Box3f& box, int n) {
    const float diag = length(box.extent());
    std::uniform_real_distribution<float> u(0, 1);
    for (int i = 0; i < n; ++i) {
        Rayf r;
        r.org = random_point(rng, box);
        r.dir = random_direction(rng);
        if (i % 2) r.tnear = u(rng) * 0.5f * diag;
        if (i % 3 == 0) r.tfar = r.tnear + u(rng) * 0.5f * diag;
        rays.push_back(r);
    }
}

/// Appends n rays from corner()s in random directions (every third) and
/// through them from random points of `box` grown by half.
template <class Corner>
void append_corner_rays(std::vector<Rayf>& rays, std::mt19937& rng, const Box3f& box, Corner&& corner, int n) {
    for (int i = 0; i < n; ++i) {
        Rayf r;
        const Vec3f c = corner();
        if (i % 3 == 0) {
            r.org = c;
            r.dir = random_direction(rng);
        } else {
            r.org = random_point(rng, grown(box, 0.5f));
            r.dir = c - r.org;
            if (!(dot(r.dir, r.dir) > 0)) r.dir = {1, 1, 1};
        }
        rays.push_back(r);
    }
}

/// Appends n rays from random points on the faces of `box` (face i % 6 in
/// turn): inwards, and every fourth along the face (that direction
/// component +-0).
inline void append_face_rays(std::vector<Rayf>& rays, std::mt19937& rng, const Box3f& box, int n) {
    for (int i = 0; i < n; ++i) {
        const int a = i % 3;
        const bool hi = (i / 3) % 2;
        Rayf r;
        r.org = random_point(rng, box);
        r.org[a] = hi ? box.hi[a] : box.lo[a];
        r.dir = random_direction(rng);
        r.dir[a] = i % 4 == 0 ? signed_zero(rng) : (hi ? -1.0f : 1.0f) * std::fabs(r.dir[a]);
        rays.push_back(r);
    }
}

/// `n` rays along cell diagonals through cell corners (`corner()`), from 1 to
/// 4 diagonals before one: ties between all three axes at every plane.
/// `diagonal()` gives a diagonal's extent before its signs are drawn.
template <class Diagonal, class Corner>
void append_diagonal_rays(std::vector<Rayf>& rays, std::mt19937& rng, Diagonal&& diagonal, Corner&& corner, int n) {
    for (int i = 0; i < n; ++i) {
        Rayf r;
        Vec3f d = diagonal();
        for (int a = 0; a < 3; ++a)
            if (rng() % 2) d[a] = -d[a];
        r.org = corner() - d * float(1 + rng() % 4);
        r.dir = d;
        rays.push_back(r);
    }
}

/// n rays from far away (10 diagonals of `box`), each aimed at a random point of it.
inline void append_far_rays(std::vector<Rayf>& rays, std::mt19937& rng, const Box3f& box, int n) {
    const float diag = length(box.extent());
    for (int i = 0; i < n; ++i) {
        Rayf r;
        const Vec3f target = random_point(rng, box);
        r.org = target - random_direction(rng) * (10.0f * diag);
        r.dir = target - r.org;
        rays.push_back(r);
    }
}

/// Appends n rays from random points of `origins` aimed exactly at a random
/// primitive's first triangle vertex, sphere pole or cone apex (none for an
/// empty scene).
inline void append_vertex_rays(std::vector<Rayf>& rays, const Scene& scene, std::mt19937& rng, const Box3f& origins,
                               int n) {
    const auto nprims = std::uint32_t(scene.primitive_count());
    for (int i = 0; i < n && nprims; ++i) {
        const PrimRef ref = scene.prims[rng() % nprims];
        Vec3f target;
        if (ref.kind == PrimKind::Triangle) {
            target = scene.triangles.p0[ref.index];
        } else if (ref.kind == PrimKind::Sphere) {
            target = scene.spheres.center[ref.index];
            target[int(rng() % 3)] += scene.spheres.radius[ref.index];
        } else {
            target = scene.cones.apex[ref.index];
        }
        Rayf r;
        r.org = random_point(rng, origins);
        r.dir = target - r.org;
        if (!(dot(r.dir, r.dir) > 0)) r.dir = {0, 0, 1};
        rays.push_back(r);
    }
}

inline std::vector<Rayf> shadow_rays(const Scene& scene, const std::vector<Rayf>& rays, const std::vector<Hitf>& hits) {
    std::vector<Rayf> out;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!hits[i].found()) continue;
        const Vec3f p = rays[i].org + rays[i].dir * hits[i].t;
        for (const PointLight& light : scene.lights) {
            Rayf s;
            s.org = p;
            s.dir = light.position - p;
            s.tnear = 1e-4f;
            s.tfar = 1.0f - 1e-4f;
            out.push_back(s);
        }
    }
    return out;
}

/// A kernel may report a hit whose point lies outside the primitive's own
/// bounding box: Moeller-Trumbore for a ray in the plane y = 0 and a triangle
/// whose highest vertex is at y = -1.8e-16 (teapot), the algebraic sphere
/// test on small far spheres (cancellation, kernels/sphere.h). No bounding
/// volume structure can reproduce such hits, so a mismatch is excused (and
/// counted) when every hit the structure missed is one.
inline bool outside_own_box(const Scene& scene, const Rayf& ray, std::uint32_t prim, float t) {
    const Box3f b = primitive_bounds(scene, prim);
    for (int a = 0; a < 3; ++a) {
        const double p = double(ray.org[a]) + double(t) * double(ray.dir[a]);
        if (p < double(b.lo[a]) || p > double(b.hi[a])) return true;
    }
    return false;
}

/// True if some primitive is hit within [tnear, tfar] at a point inside its box.
inline bool hit_inside_own_box(const Scene& scene, const KernelChoice& kernels, const Rayf& ray) {
    const PrimitiveIntersector<float> isect{&scene, kernels};
    for (std::uint32_t p = 0; p < scene.primitive_count(); ++p) {
        Rayf r = ray;
        Hitf h;
        if (isect.intersect(p, r, h) && !outside_own_box(scene, ray, p, h.t)) return true;
    }
    return false;
}

/// The same hit or miss; the same primitive at the same t, or another one
/// at t within relative 1e-5 (a shared edge or vertex).
inline bool same_closest_hit(const Hitf& want, const Hitf& got) {
    if (want.found() != got.found()) return false;
    if (!want.found()) return true;
    return want.prim == got.prim ? want.t == got.t
                                 : std::fabs(want.t - got.t) <= 1e-5f * std::max(std::fabs(want.t), std::fabs(got.t));
}

struct Mismatches {
    std::size_t count = 0;
    std::size_t excused = 0;  ///< oracle hits outside their primitive's box (see outside_own_box)
    std::string first;        ///< the first few, with reproducing rays
};

/// Closest hits `got` against the oracle's `want` (same_closest_hit); a
/// missed nearer oracle hit outside its primitive's box is excused. The
/// first `examples` mismatches are described in Mismatches::first.
inline Mismatches compare_hits(const Scene& scene, const std::vector<Rayf>& rays, const std::vector<Hitf>& want,
                               const std::vector<Hitf>& got, std::size_t examples) {
    Mismatches m;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (same_closest_hit(want[i], got[i])) continue;
        // Missed the oracle's (nearer) hit: excused if that hit is outside its box.
        if (want[i].found() && (!got[i].found() || got[i].t > want[i].t) &&
            outside_own_box(scene, rays[i], want[i].prim, want[i].t)) {
            ++m.excused;
            continue;
        }
        if (++m.count <= examples)
            m.first += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    brute " + describe(want[i]) +
                       ", got " + describe(got[i]);
    }
    return m;
}

/// Occlusion answers `got` against the oracle's `want`; an oracle "occluded"
/// is excused when no hit lies inside its primitive's box.
inline Mismatches compare_occluded(const Scene& scene, const KernelChoice& kernels, const std::vector<Rayf>& rays,
                                   const std::vector<std::uint8_t>& want, const std::vector<std::uint8_t>& got,
                                   std::size_t examples) {
    Mismatches m;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (want[i] == got[i]) continue;
        if (want[i] && !hit_inside_own_box(scene, kernels, rays[i])) {
            ++m.excused;
            continue;
        }
        if (++m.count <= examples)
            m.first += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    brute " +
                       (want[i] ? "occluded" : "clear") + ", got " + (got[i] ? "occluded" : "clear");
    }
    return m;
}

inline std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string s = info.param;
    std::replace(s.begin(), s.end(), '.', '_');
    return s;
}

}  // namespace raypack::oracle_harness
