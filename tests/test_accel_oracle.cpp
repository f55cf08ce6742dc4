// Every acceleration structure against the brute-force oracle, on every
// shared scene: camera rays, random rays, adversarial rays and shadow rays.
// bvh2 runs the very same primitive kernels as the oracle, so it must agree
// exactly: the same hit or miss on every ray, the same t for the same
// primitive, and another primitive only at a shared edge or vertex (t within
// 1e-5). Embree uses its own kernels and is held to an agreement fraction
// instead, on the rays whose answer does not hinge on rounding.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tests/oracle_harness.h"
#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "render/camera_rays.h"
#include "scene/load.h"

namespace raypack {

using namespace raypack::oracle_harness;
namespace {


std::vector<std::string> accel_kinds_under_test() {
    std::vector<std::string> kinds = {"bvh2"};
#ifdef RAYPACK_HAVE_EMBREE
    kinds.push_back("embree");
    kinds.push_back("embree-robust");
#endif
    return kinds;
}

/// Both structures on both cores; Accel::intersect / occluded are const.
std::vector<Hitf> trace(const Accel& accel, const std::vector<Rayf>& rays) {
    std::vector<Hitf> hits(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 64), [&](const auto& r) {
        accel.intersect(std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                        std::span<Hitf>(hits).subspan(r.begin(), r.size()));
    });
    return hits;
}

std::vector<std::uint8_t> trace_occluded(const Accel& accel, const std::vector<Rayf>& rays) {
    std::vector<std::uint8_t> occ(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 64), [&](const auto& r) {
        accel.occluded(std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                       std::span<std::uint8_t>(occ).subspan(r.begin(), r.size()));
    });
    return occ;
}

bool same_t(float a, float b, float rel) { return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)); }

// ---- Ray sets ------------------------------------------------------------------

/// A point of primitive p that lies on its bounding box (a vertex, the top of
/// a sphere, the rim of a cone end): rays through such points test whether the
/// structure's boxes are conservative.
Vec3f extreme_point(const Scene& s, std::uint32_t p, std::mt19937& rng) {
    const PrimRef ref = s.prims[p];
    const std::uint32_t i = ref.index;
    switch (ref.kind) {
        case PrimKind::Triangle: {
            const int k = int(rng() % 3);
            return k == 0 ? s.triangles.p0[i] : k == 1 ? s.triangles.p1[i] : s.triangles.p2[i];
        }
        case PrimKind::Sphere: {
            Vec3f c = s.spheres.center[i];
            const int a = int(rng() % 3);
            c[a] += (rng() % 2 ? 1.0f : -1.0f) * s.spheres.radius[i];
            return c;
        }
        case PrimKind::Cone:
            return rng() % 2 ? s.cones.base[i] : s.cones.apex[i];
        case PrimKind::HeightField: return s.height_fields[i].peak();
        case PrimKind::Instance: return s.instances[i].bounds.center();
    }
    return {};
}

std::vector<Rayf> adversarial_rays(const Scene& scene, std::mt19937& rng) {
    std::vector<Rayf> rays;
    const Box3f box = scene_bounds(scene);
    const auto nprims = std::uint32_t(scene.primitive_count());
    std::uniform_real_distribution<float> u(0, 1);
    auto axis_dir = [&](int axis, float sign) {
        Vec3f d{signed_zero(rng), signed_zero(rng), signed_zero(rng)};
        d[axis] = sign;
        return d;
    };
    // 1. Axis-parallel rays with +-0 in the other components, from random
    //    origins and through extreme points of primitives (which lie on the
    //    faces of the leaf boxes), starting outside the scene box.
    for (int i = 0; i < 600; ++i) {
        const int axis = i % 3;
        const float sign = (i / 3) % 2 ? 1.0f : -1.0f;
        Rayf r;
        r.org = i < 200 ? random_point(rng, box) : extreme_point(scene, std::uint32_t(rng() % nprims), rng);
        r.org[axis] = sign > 0 ? box.lo[axis] - 1.0f : box.hi[axis] + 1.0f;
        r.dir = axis_dir(axis, sign);
        rays.push_back(r);
    }
    // 2. Origins exactly on the faces of the scene box, directions into the
    //    box and directions parallel to the face (component +-0).
    append_face_rays(rays, rng, box, 600);
    // 3. Rays grazing sphere silhouettes (distance r(1 - 1e-6), r, r(1 + 1e-6)
    //    from the centre) and aimed at triangle vertices and cone rims.
    for (int i = 0; i < 900; ++i) {
        const std::uint32_t p = std::uint32_t(rng() % nprims);
        const PrimRef ref = scene.prims[p];
        Rayf r;
        if (ref.kind == PrimKind::Sphere) {
            const Vec3f c = scene.spheres.center[ref.index];
            const float rad = scene.spheres.radius[ref.index];
            const Vec3f d = random_direction(rng);
            Vec3f e = cross(d, random_direction(rng));
            e = normalize(e);
            const float f = i % 3 == 0 ? 1.0f - 1e-6f : i % 3 == 1 ? 1.0f : 1.0f + 1e-6f;
            r.org = c + e * (rad * f) - d * (rad * (2.0f + 4.0f * u(rng)));
            r.dir = d;
        } else {
            const Vec3f target = extreme_point(scene, p, rng);
            r.org = random_point(rng, box);
            r.dir = target - r.org;
            if (!(dot(r.dir, r.dir) > 0)) r.dir = {1, 0, 0};
        }
        rays.push_back(r);
    }
    return rays;
}

// ---- Comparisons -----------------------------------------------------------------

struct Agreement {
    std::size_t rays = 0, mismatches = 0;
    std::string first;  ///< the first few mismatches, with reproducing rays
    double fraction() const { return rays ? 1.0 - double(mismatches) / double(rays) : 1.0; }
};

/// Closest hit: the same hit or miss, and t within `rel` relative or `abs`
/// (a length, for hits just in front of the origin). The primitive may differ
/// only where two are hit at (nearly) the same t: a shared edge or vertex.
/// `same_kernels`: the same primitive must then give the very same t.
Agreement compare_hits(const std::vector<Rayf>& rays, const std::vector<Hitf>& want, const std::vector<Hitf>& got,
                       float rel, float abs, bool same_kernels) {
    Agreement a;
    a.rays = rays.size();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        bool ok = want[i].found() == got[i].found();
        if (ok && want[i].found())
            ok = same_kernels && want[i].prim == got[i].prim
                     ? want[i].t == got[i].t
                     : same_t(want[i].t, got[i].t, rel) || std::fabs(want[i].t - got[i].t) * length(rays[i].dir) <= abs;
        if (ok) continue;
        if (++a.mismatches <= 5)
            a.first += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    brute " + describe(want[i]) +
                       ", got " + describe(got[i]);
    }
    return a;
}

Agreement compare_occluded(const std::vector<Rayf>& rays, const std::vector<std::uint8_t>& want,
                           const std::vector<std::uint8_t>& got) {
    Agreement a;
    a.rays = rays.size();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (want[i] == got[i]) continue;
        if (++a.mismatches <= 5)
            a.first += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    brute " +
                       (want[i] ? "occluded" : "clear") + ", got " + (got[i] ? "occluded" : "clear");
    }
    return a;
}

/// Rays whose brute-force answer (hit or miss, and which primitive) stays the
/// same when the ray is moved sideways by `delta` in four directions. Tracers
/// with different kernels must agree on these; on the others (grazing a
/// silhouette, through an edge or a vertex, inside a face's plane) either
/// answer is defensible.
std::vector<std::uint8_t> stable_rays(const Accel& brute, const std::vector<Rayf>& rays,
                                      const std::vector<Hitf>& truth, float delta) {
    std::vector<std::uint8_t> stable(rays.size(), 1);
    for (int k = 0; k < 4; ++k) {
        std::vector<Rayf> moved = rays;
        for (Rayf& r : moved) {
            const Vec3f d = normalize(r.dir);
            const Vec3f helper = std::fabs(d.x) < 0.5f ? Vec3f{1, 0, 0} : Vec3f{0, 1, 0};
            const Vec3f e1 = normalize(cross(d, helper)), e2 = cross(d, e1);
            r.org += (k < 2 ? e1 : e2) * (k % 2 ? delta : -delta);
        }
        const std::vector<Hitf> hits = trace(brute, moved);
        for (std::size_t i = 0; i < rays.size(); ++i)
            if (hits[i].prim != truth[i].prim) stable[i] = 0;
    }
    return stable;
}

class AccelOracle : public ::testing::TestWithParam<std::string> {};

TEST_P(AccelOracle, MatchesBruteForce) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    ASSERT_GT(scene.primitive_count(), 0u);
    const BruteForce brute(scene, KernelChoice{});
    std::mt19937 rng(20240601);

    struct Set {
        const char* name;
        std::vector<Rayf> rays;
    };
    std::vector<Set> sets;
    sets.push_back({"camera", camera_rays(scene, 64)});
    sets.push_back({"random", random_rays(scene, rng, 2000)});
    sets.push_back({"adversarial", adversarial_rays(scene, rng)});
    std::vector<std::vector<Hitf>> truth;
    for (const Set& s : sets) truth.push_back(trace(brute, s.rays));
    const float scene_size = length(scene_bounds(scene).extent());
    const float delta = 1e-5f * scene_size;
    const std::vector<std::uint8_t> adversarial_stable = stable_rays(brute, sets[2].rays, truth[2], delta);
    const std::vector<Rayf> shadows = shadow_rays(scene, sets[0].rays, truth[0]);
    const std::vector<std::uint8_t> shadow_truth = trace_occluded(brute, shadows);

    for (const std::string& kind : accel_kinds_under_test()) {
        SCOPED_TRACE(kind);
        AccelConfig config;
        config.kind = kind;
        const std::unique_ptr<Accel> accel = build_accel(scene, config);
        const bool exact = kind == "bvh2";
        for (std::size_t k = 0; k < sets.size(); ++k) {
            const std::vector<Hitf> got = trace(*accel, sets[k].rays);
            if (exact) {
                const Agreement a = compare_hits(sets[k].rays, truth[k], got, 1e-5f, 0.0f, true);
                EXPECT_EQ(a.mismatches, 0u) << GetParam() << " " << sets[k].name << ": " << a.mismatches << " of "
                                            << a.rays << " rays differ from brute force" << a.first;
                continue;
            }
            // Different kernels: compare camera and random rays, and those
            // adversarial rays whose answer does not hinge on a rounding error.
            std::vector<Rayf> rays;
            std::vector<Hitf> want, have;
            for (std::size_t i = 0; i < sets[k].rays.size(); ++i) {
                if (k == 2 && !adversarial_stable[i]) continue;
                rays.push_back(sets[k].rays[i]);
                want.push_back(truth[k][i]);
                have.push_back(got[i]);
            }
            const Agreement a = compare_hits(rays, want, have, 1e-4f, 1e-6f * scene_size, false);
            EXPECT_GE(a.fraction(), 0.999) << GetParam() << " " << sets[k].name << ": " << a.mismatches << " of "
                                           << a.rays << " rays differ from brute force" << a.first;
        }
        const Agreement a = compare_occluded(shadows, shadow_truth, trace_occluded(*accel, shadows));
        if (exact) {
            EXPECT_EQ(a.mismatches, 0u) << GetParam() << " shadow: " << a.mismatches << " of " << a.rays
                                        << " occlusion answers differ" << a.first;
        } else {
            EXPECT_GE(a.fraction(), 0.999) << GetParam() << " shadow: " << a.mismatches << " of " << a.rays
                                           << " occlusion answers differ" << a.first;
        }
    }
}

// Empty instantiation name: the tests are called AccelOracle.MatchesBruteForce/<scene>.
INSTANTIATE_TEST_SUITE_P(, AccelOracle, ::testing::ValuesIn(shared_scene_files()), param_name);

// ---- Hand-made cases that the scenes reach only by luck --------------------------

Scene one_sphere() {
    Scene s;
    s.materials.push_back({});
    s.add_sphere({0, 0, 0}, 1, 0);
    s.update_features();
    return s;
}

TEST_F(AccelOracle, RayInBoxPlaneWithNegativeZeroDirection) {
    // A ray in the plane y = 1 touches the unit sphere at (0, 1, 0): the
    // geometric kernel finds d2 == r2 exactly, so brute force reports a hit at
    // t = 5 whatever the sign of dir.y. The sphere's box has its top face in
    // that plane; a structure must not cull the box for either sign of zero.
    const Scene scene = one_sphere();
    const BruteForce brute(scene, KernelChoice{});
    for (const std::string& kind : accel_kinds_under_test()) {
        if (kind != "bvh2") continue;  // Embree's sphere test need not call a tangent a hit
        AccelConfig config;
        config.kind = kind;
        const std::unique_ptr<Accel> accel = build_accel(scene, config);
        for (float y : {1.0f, -1.0f}) {
            for (float zero : {0.0f, -0.0f}) {
                Rayf r;
                r.org = {-5, y, 0};
                r.dir = {1, zero, 0};
                const Hitf want = brute.intersect1(r);
                ASSERT_TRUE(want.found());
                EXPECT_EQ(want.t, 5.0f);
                const Hitf got = accel->intersect1(r);
                EXPECT_TRUE(got.found()) << kind << ": " << describe(r);
                EXPECT_EQ(got.t, want.t) << kind << ": " << describe(r);
                EXPECT_EQ(accel->occluded1(r), brute.occluded1(r)) << kind << ": " << describe(r);
            }
        }
    }
}

TEST_F(AccelOracle, EmptySceneMissesEverything) {
    Scene scene;
    for (const std::string& kind : accel_kinds_under_test()) {
        AccelConfig config;
        config.kind = kind;
        const std::unique_ptr<Accel> accel = build_accel(scene, config);
        Rayf r;
        r.org = {0, 0, 0};
        r.dir = {1, 1, 1};
        EXPECT_FALSE(accel->intersect1(r).found()) << kind;
        EXPECT_FALSE(accel->occluded1(r)) << kind;
    }
}

TEST_F(AccelOracle, BuildAccelTimesEveryStructure) {
    // build_accel measures each construction, its statistics included; the
    // structures do not time themselves, so one constructed directly reports
    // no build time. An instanced or moving scene reports its whole build
    // (objects, top structure, motion BVH).
    const Scene teapot = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff");
    for (const char* kind : accel_kinds()) EXPECT_GT(build_accel(teapot, accel_config(kind))->stats().build_ms, 0.0) << kind;
    EXPECT_EQ(BruteForce(teapot, KernelChoice{}).stats().build_ms, 0.0);
    for (const char* spec : {"gen:tetra-instanced:4", "gen:balls:2:motion"}) {
        const Scene scene = load_scene(spec);
        EXPECT_TRUE(scene.placements() || !scene.moving_instances.empty()) << spec;
        EXPECT_GT(build_accel(scene, accel_config("bvh4"))->stats().build_ms, 0.0) << spec;
    }
}

TEST_F(AccelOracle, QueriesWriteEveryAnswer) {
    // The renderers hand the structures hit and occlusion buffers they have
    // not initialised (render/append_buffer.h): every query must write every
    // answer, misses included. Buffers filled with a poison that looks like
    // a hit on primitive 0 must come back as fresh ones do, bit for bit, for
    // every structure, query, packet width and kind of scene.
    Hitf poison;
    poison.t = -7.0f;
    poison.prim = 0;
    poison.u = poison.v = std::numeric_limits<float>::quiet_NaN();
    const auto same = [](const Hitf& a, const Hitf& b) {
        return std::memcmp(&a, &b, sizeof(Hitf)) == 0;
    };
    for (const char* spec : {"gen:balls:2", "gen:teapot:4", "gen:tetra-instanced:3", "gen:balls:2:motion"}) {
        const Scene scene = load_scene(spec);
        std::vector<Rayf> rays = camera_rays(scene, 24);
        for (std::size_t i = 0; i < rays.size(); i += 3) rays[i].dir = -rays[i].dir;  // away from the scene: misses
        std::vector<Hitf> first(rays.size());
        build_accel(scene, accel_config("brute"))->intersect(rays, first);
        const std::vector<Rayf> shadows = shadow_rays(scene, rays, first);
        const auto times_for = [](std::size_t n) {
            std::vector<float> t(n);
            for (std::size_t i = 0; i < n; ++i) t[i] = float(i % 7) / 6.0f;
            return t;
        };
        const std::vector<float> times = times_for(rays.size()), shadow_times = times_for(shadows.size());
        for (const char* kind : accel_kinds()) {
            SCOPED_TRACE(std::string(spec) + " " + kind);
            const bool embree = std::string(kind).starts_with("embree");
            if (embree && (scene.placements() || !scene.moving_instances.empty())) continue;  // raypack's own only
            const std::unique_ptr<Accel> accel = build_accel(scene, accel_config(kind));
            for (int width : {1, 4, 8, 16}) {
                if (width > 1 && !accel->supports_packet(width)) continue;
                for (const bool timed : {false, true}) {
                    std::vector<Hitf> fresh(rays.size()), dirty(rays.size(), poison);
                    std::vector<std::uint8_t> open(shadows.size()), smudged(shadows.size(), 0xAB);
                    if (timed) {
                        accel->intersect_at(width, rays, times, fresh);
                        accel->intersect_at(width, rays, times, dirty);
                        accel->occluded_at(width, shadows, shadow_times, open);
                        accel->occluded_at(width, shadows, shadow_times, smudged);
                    } else if (width == 1) {
                        accel->intersect(rays, fresh);
                        accel->intersect(rays, dirty);
                        accel->occluded(shadows, open);
                        accel->occluded(shadows, smudged);
                    } else {
                        accel->intersect_packets(width, rays, fresh);
                        accel->intersect_packets(width, rays, dirty);
                        accel->occluded_packets(width, shadows, open);
                        accel->occluded_packets(width, shadows, smudged);
                    }
                    std::size_t misses = 0, unwritten = 0;
                    for (std::size_t i = 0; i < rays.size(); ++i) {
                        misses += !fresh[i].found();
                        unwritten += !same(fresh[i], dirty[i]);
                    }
                    EXPECT_GT(misses, 0u) << "width " << width;  // the poison is tested on misses too
                    EXPECT_EQ(unwritten, 0u) << "width " << width << (timed ? " at times" : "");
                    EXPECT_EQ(open, smudged) << "width " << width << (timed ? " at times" : "");
                }
            }
        }
    }
}

TEST_F(AccelOracle, UnknownKindThrows) {
    const Scene scene = one_sphere();
    AccelConfig config;
    config.kind = "octree-of-dreams";
    EXPECT_THROW(build_accel(scene, config), std::invalid_argument);
    // Every advertised kind builds.
    for (const char* kind : accel_kinds()) {
        config.kind = kind;
        EXPECT_NE(build_accel(scene, config), nullptr) << kind;
    }
}

}  // namespace
}  // namespace raypack
