// Height fields (kernels/height_field.h, NFF `hf`): the walk against a
// double-precision brute-force reference, planar patches against their
// triangles, every structure against the brute-force oracle, the `hf`
// syntax and its errors, the image form, and the terrain generator.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "kernels/height_field_walk.h"
#include "oracle_harness.h"
#include "scene_errors.h"
#include "render/image.h"
#include "scene/height_field_mesh.h"
#include "scene/load.h"
#include "scene/nff_text.h"

namespace raypack {
namespace {

using namespace oracle_harness;

/// nx x ny samples over [lo.x, hi.x] x [lo.y, hi.y], heights from h(x, y).
template <class H>
HeightField make_field(std::uint32_t nx, std::uint32_t ny, Vec3f lo, Vec3f hi, H&& h) {
    HeightField f;
    f.lo = lo;
    f.hi = hi;
    f.nx = nx;
    f.ny = ny;
    f.z.resize(std::size_t(nx) * ny);
    for (std::uint32_t j = 0; j < ny; ++j)
        for (std::uint32_t i = 0; i < nx; ++i)
            f.z[std::size_t(j) * nx + i] = h(lo.x + (hi.x - lo.x) * float(i) / float(nx - 1),
                                             lo.y + (hi.y - lo.y) * float(j) / float(ny - 1), i, j);
    f.build_ranges();
    return f;
}

/// The reference: every cell's bilinear patch solved in double in the
/// ray's own t (no walk, no pyramid, no local coordinates), the nearest
/// root in [tnear, tfar] whose (s, r) lies in the cell. `slope` gets how
/// fast the ray's height leaves the surface's there (dz / dt): a t error
/// times it is a height error.
bool reference_hit(const HeightField& f, const Ray<double>& ray, double& t_best, double* slope = nullptr) {
    const double sx = (double(f.hi.x) - f.lo.x) / f.cells_x(), sy = (double(f.hi.y) - f.lo.y) / f.cells_y();
    bool found = false;
    t_best = ray.tfar;
    for (std::uint32_t j = 0; j < f.cells_y(); ++j)
        for (std::uint32_t i = 0; i < f.cells_x(); ++i) {
            const double h00 = f.sample(i, j), h10 = f.sample(i + 1, j), h01 = f.sample(i, j + 1),
                         h11 = f.sample(i + 1, j + 1);
            const double b = h10 - h00, c = h01 - h00, e = h00 - h10 - h01 + h11;
            const double s0 = (ray.org.x - (f.lo.x + i * sx)) / sx, ds = ray.dir.x / sx;
            const double r0 = (ray.org.y - (f.lo.y + j * sy)) / sy, dr = ray.dir.y / sy;
            // o.z + t d.z = h00 + b s + c r + e s r, with s = s0 + t ds, r = r0 + t dr.
            const double qa = -e * ds * dr;
            const double qb = ray.dir.z - (b * ds + c * dr + e * (s0 * dr + r0 * ds));
            const double qc = ray.org.z - (h00 + b * s0 + c * r0 + e * s0 * r0);
            double roots[2];
            int n = 0;
            if (qa == 0) {
                if (qb != 0) roots[n++] = -qc / qb;
            } else {
                const double disc = qb * qb - 4 * qa * qc;
                if (disc >= 0) {
                    roots[n++] = (-qb - std::sqrt(disc)) / (2 * qa);
                    roots[n++] = (-qb + std::sqrt(disc)) / (2 * qa);
                }
            }
            for (int k = 0; k < n; ++k) {
                const double t = roots[k], s = s0 + t * ds, r = r0 + t * dr;
                if (t >= ray.tnear && t <= t_best && s >= -1e-12 && s <= 1 + 1e-12 && r >= -1e-12 && r <= 1 + 1e-12) {
                    t_best = t;
                    found = true;
                    if (slope) *slope = std::abs(2 * qa * t + qb);
                }
            }
        }
    return found;
}

Ray<double> to_double(const Rayf& r) { return {Vec3<double>(r.org), Vec3<double>(r.dir), r.tnear, r.tfar}; }

/// Rays at a field from around it: aimed at random points of the surface's
/// box, grazing (nearly horizontal), vertical, from below, and some with a
/// finite tfar.
std::vector<Rayf> rays_at(const HeightField& f, std::mt19937& rng, int n) {
    const Box3f box{f.lo, f.hi};
    const Box3f around = grown(box, 0.5f);
    // The box, at least a tenth of its width deep (a flat field's box is a
    // plane: origins in it would all lie on the surface).
    Box3f inside = box;
    const float depth = std::max(0.0f, 0.1f * (f.hi.x - f.lo.x) - (f.hi.z - f.lo.z));
    inside.lo.z -= depth;
    inside.hi.z += depth;
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<Rayf> rays;
    for (int k = 0; k < n; ++k) {
        Rayf r;
        const Vec3f target = random_point(rng, box);
        switch (k % 5) {
            case 0: r.org = random_point(rng, around); break;
            case 1:  // grazing: from the side at about the surface's height
                r.org = random_point(rng, around);
                r.org.z = target.z + (u(rng) - 0.5f) * 0.02f * (inside.hi.z - inside.lo.z);
                break;
            case 2:  // vertical, down or up
                r.org = {target.x, target.y, k % 2 ? f.hi.z + 1.0f : f.lo.z - 1.0f};
                break;
            case 3: r.org = random_point(rng, inside); break;  // either side of the surface
            default: r.org = random_point(rng, around); break;
        }
        r.dir = target - r.org;
        if (k % 5 == 2) r.dir.x = r.dir.y = 0.0f;
        if (!(dot(r.dir, r.dir) > 0)) r.dir = {0, 0, -1};
        if (k % 7 == 0) r.tfar = u(rng) * 1.5f;
        // What a .rays file may hold: an unbounded interval both ways, a zero direction.
        if (k % 97 == 5) r.tnear = -std::numeric_limits<float>::infinity();
        if (k % 97 == 6) r.dir = {0, 0, 0};
        if (k % 97 == 7) r.tnear = -std::numeric_limits<float>::infinity(), r.dir = {0, 0, 0};
        rays.push_back(r);
    }
    return rays;
}

/// Whether the reference's answer (hit or miss; the hit's height within
/// `delta`) moves when the origin moves by `delta` along an axis: the ray
/// is then within that margin of a silhouette, an edge or a tangent, where
/// float and double may differ.
bool reference_is_marginal(const HeightField& f, const Ray<double>& ray, double delta) {
    double t0, slope = 0;
    const bool hit0 = reference_hit(f, ray, t0, &slope);
    for (int a = 0; a < 3; ++a)
        for (double sign : {-1.0, 1.0}) {
            Ray<double> p = ray;
            p.org[a] += sign * delta;
            double t;
            const bool hit = reference_hit(f, p, t);
            if (hit != hit0 || (hit && std::abs(t - t0) * slope > delta)) return true;
        }
    return false;
}

struct FieldCase {
    const char* name;
    HeightField field;
};

std::vector<FieldCase> field_cases() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<FieldCase> cases;
    cases.push_back({"smooth", make_field(17, 17, {0, 0, 0}, {1, 1, 0}, [](float x, float y, auto, auto) {
                         return 0.3f * std::sin(6 * x) * std::cos(5 * y);
                     })});
    cases.push_back({"noise", make_field(13, 9, {-2, 1, 0}, {3, 2, 0}, [&](float, float, auto, auto) {
                         return u(rng) * 0.5f;
                     })});
    cases.push_back({"one cell", make_field(2, 2, {0, 0, 0}, {1, 1, 0}, [](float, float, auto i, auto j) {
                         return float(i) * 0.7f - float(j) * 0.3f + float(i * j) * 0.9f;
                     })});
    cases.push_back({"far from the origin", make_field(33, 21, {1000, -500, 0}, {1010, -490, 0},
                                                       [&](float x, float y, auto, auto) {
                                                           return 200.0f + std::sin(x) + std::cos(0.5f * y);
                                                       })});
    cases.push_back({"flat", make_field(9, 9, {0, 0, 0}, {1, 1, 0}, [](float, float, auto, auto) { return 0.25f; })});
    return cases;
}

TEST(HeightField, WalkAgreesWithDoubleReference) {
    // Float and double walks against the reference: the same hit or miss,
    // and hit heights (t error times the reference's dz/dt) within `bound`
    // (double: 1e-4 of it), except where the reference's own answer moves
    // when the origin moves by `bound` (silhouettes, cell edges, tangents).
    // The bound: 1e-5 of the field's size, or 64 float ulps of the largest
    // coordinate in play, whichever is larger (floats resolve no finer).
    for (const FieldCase& c : field_cases()) {
        const HeightField& f = c.field;
        const double size = std::max({double(f.hi.x) - f.lo.x, double(f.hi.y) - f.lo.y, double(f.hi.z) - f.lo.z});
        const double magnitude = std::max({std::abs(f.lo.x), std::abs(f.lo.y), std::abs(f.lo.z), std::abs(f.hi.x),
                                           std::abs(f.hi.y), std::abs(f.hi.z)}) + size;
        const double bound = std::max(1e-5 * size, 64 * 0x1p-23 * magnitude);
        std::mt19937 rng(11);
        const std::vector<Rayf> rays = rays_at(f, rng, 4000);
        int hits = 0, marginal = 0, float_bad = 0, double_bad = 0;
        std::string first, first_marginal;
        for (const Rayf& ray : rays) {
            const Ray<double> rd = to_double(ray);
            double t_ref, slope = 0;
            const bool ref = reference_hit(f, rd, t_ref, &slope);
            hits += ref;
            float tf = 0, uf = 0, vf = 0;
            const bool got_f = intersect_height_field(f, ray, tf, uf, vf);
            double td = 0, ud = 0, vd = 0;
            const bool got_d = intersect_height_field(f, rd, td, ud, vd);
            const bool f_ok = got_f == ref && (!ref || std::abs(tf - t_ref) * slope <= bound);
            const bool d_ok = got_d == ref && (!ref || std::abs(td - t_ref) * slope <= 1e-4 * bound);
            if (f_ok && d_ok) continue;
            const bool is_marginal = reference_is_marginal(f, rd, bound);
            marginal += is_marginal;
            float_bad += !is_marginal && !f_ok;
            double_bad += !is_marginal && !d_ok;
            std::string& example = is_marginal ? first_marginal : first;
            if (example.empty())
                example = describe(ray) + ": reference " + (ref ? std::to_string(t_ref) : "miss") + ", float " +
                        (got_f ? std::to_string(tf) : "miss") + ", double " + (got_d ? std::to_string(td) : "miss");
        }
        EXPECT_EQ(float_bad, 0) << c.name << ": " << first;
        EXPECT_EQ(double_bad, 0) << c.name << ": " << first;
        EXPECT_GT(hits, 400) << c.name;  // the rays do reach the surface
        EXPECT_LT(marginal, 40) << c.name << ": " << first_marginal;
    }
}

template <int K>
void expect_lanes_equal_scalar() {
    // The lockstep walk of K rays gives each lane the scalar walk's bits.
    using F = vfloat<K>;
    for (const FieldCase& c : field_cases()) {
        std::mt19937 rng(17);
        const std::vector<Rayf> rays = rays_at(c.field, rng, 64 * K);
        int hits = 0;
        for (std::size_t first = 0; first < rays.size(); first += K) {
            alignas(64) float ox[K], oy[K], oz[K], dx[K], dy[K], dz[K], tn[K], tf[K], on[K];
            for (int k = 0; k < K; ++k) {
                const Rayf& r = rays[first + k];
                ox[k] = r.org.x, oy[k] = r.org.y, oz[k] = r.org.z, dx[k] = r.dir.x, dy[k] = r.dir.y, dz[k] = r.dir.z;
                tn[k] = r.tnear, tf[k] = r.tfar, on[k] = k % 5 == 4 ? 0.0f : 1.0f;  // some lanes off
            }
            const mask_of<F> active = F::load_aligned(on) > F(0.0f);
            const Vec3<F> org{F::load_aligned(ox), F::load_aligned(oy), F::load_aligned(oz)};
            const Vec3<F> dir{F::load_aligned(dx), F::load_aligned(dy), F::load_aligned(dz)};
            F t(-1.0f), u(-1.0f), v(-1.0f);
            const std::uint32_t bits = mask_bits(intersect_height_field_lanes<F>(
                c.field, active, org, dir, F::load_aligned(tn), F::load_aligned(tf), t, u, v));
            for (int k = 0; k < K; ++k) {
                float ts = -1, us = -1, vs = -1;
                const bool want = on[k] != 0 && intersect_height_field(c.field, rays[first + k], ts, us, vs);
                ASSERT_EQ(((bits >> k) & 1u) != 0, want) << c.name << " " << describe(rays[first + k]);
                if (!want) continue;
                ++hits;
                EXPECT_EQ(std::bit_cast<std::uint32_t>(lane(t, k)), std::bit_cast<std::uint32_t>(ts)) << c.name;
                EXPECT_EQ(lane(u, k), us) << c.name;
                EXPECT_EQ(lane(v, k), vs) << c.name;
            }
        }
        EXPECT_GT(hits, 8 * K) << c.name;
    }
}

TEST(HeightField, LanesEqualScalarWalk) {
    if constexpr (kWidthCompiled<4>) expect_lanes_equal_scalar<4>();
    if constexpr (kWidthCompiled<8>) expect_lanes_equal_scalar<8>();
    if constexpr (kWidthCompiled<16>) expect_lanes_equal_scalar<16>();
}

TEST(HeightField, HitPositionAndNormalAreThePatchs) {
    // u, v place the hit on the surface; the normal is the patch's gradient.
    const HeightField f = make_field(17, 17, {0, 0, 0}, {2, 1, 0}, [](float x, float y, auto, auto) {
        return 0.2f * x * x - 0.1f * y;
    });
    std::mt19937 rng(3);
    int checked = 0;
    for (const Rayf& ray : rays_at(f, rng, 500)) {
        float t, u, v;
        if (!intersect_height_field(f, ray, t, u, v)) continue;
        const Vec3f p = ray.org + ray.dir * t, q = height_field_point(f, u, v);
        EXPECT_LT(length(p - q), 1e-4f) << describe(ray);
        // z = 0.2 x^2 - 0.1 y, bilinear between samples: the slope in x is
        // within one cell's change of 0.4 x, in y exactly -0.1.
        const Vec3f n = height_field_normal(f, u, v);
        EXPECT_NEAR(-n.x, 0.4f * q.x, 0.4f * 2.0f / 16.0f + 1e-4f);
        EXPECT_NEAR(-n.y, -0.1f, 1e-4f);
        EXPECT_EQ(n.z, 1.0f);
        ++checked;
    }
    EXPECT_GT(checked, 100);
}

Scene scene_with(std::vector<HeightField> fields) {
    Scene s;
    s.materials.push_back({});
    for (HeightField& f : fields) s.add_height_field(std::move(f), 0);
    s.update_features();
    return s;
}

TEST(HeightField, PlanarPatchesAreTheirTriangles) {
    // Where every patch is planar (heights linear in x and y), the field and
    // its triangulation (--heightfield-as triangles) are the same surface.
    Scene field = scene_with({make_field(9, 7, {-1, -1, 0}, {2, 1, 0}, [](float x, float y, auto, auto) {
        return 0.3f * x - 0.2f * y + 0.1f;
    })});
    const Scene mesh = height_fields_as_triangles(field);
    ASSERT_EQ(mesh.triangles.size(), 2u * 8u * 6u);
    ASSERT_TRUE(mesh.height_fields.empty());
    const BruteForce a(field, KernelChoice{}), b(mesh, KernelChoice{});
    std::mt19937 rng(5);
    std::vector<Rayf> rays;
    std::uniform_real_distribution<float> u(0.02f, 0.98f);
    for (int k = 0; k < 3000; ++k) {
        // Aimed at interior points of the surface, from either side.
        const Vec3f target = height_field_point(field.height_fields[0], u(rng), u(rng));
        Rayf r;
        r.org = target + random_direction(rng) * 3.0f;
        r.dir = target - r.org;
        rays.push_back(r);
    }
    // The two hits lie within 1e-5 of each other's plane (a t difference
    // grows as the ray grazes the plane).
    const Vec3f n = normalize(Vec3f{-0.3f, 0.2f, 1.0f});
    int hits = 0;
    for (const Rayf& ray : rays) {
        Hitf ha, hb;
        a.intersect(std::span<const Rayf>(&ray, 1), std::span<Hitf>(&ha, 1));
        b.intersect(std::span<const Rayf>(&ray, 1), std::span<Hitf>(&hb, 1));
        ASSERT_EQ(ha.found(), hb.found()) << describe(ray);
        if (!ha.found()) continue;
        ++hits;
        EXPECT_LT(std::abs((ha.t - hb.t) * dot(ray.dir, n)), 1e-5f) << describe(ray);
    }
    EXPECT_EQ(hits, 3000);
}

/// Several fields, overlapping, with spheres and triangles among them.
Scene mixed_scene() {
    std::vector<HeightField> fields;
    fields.push_back(make_field(33, 33, {0, 0, 0}, {4, 4, 0}, [](float x, float y, auto, auto) {
        return 0.5f * std::sin(2 * x) * std::cos(3 * y);
    }));
    fields.push_back(make_field(5, 9, {1, 1, 0}, {2, 3, 0}, [](float x, float y, auto, auto) { return 0.2f + x - y; }));
    fields.push_back(make_field(65, 3, {-1, 2, 0}, {5, 2.5f, 0}, [](float x, float, auto, auto) { return 0.1f * x; }));
    Scene s = scene_with(std::move(fields));
    s.add_sphere({2, 2, 0.3f}, 0.4f, 0);
    s.add_sphere({0.5f, 3.5f, 0.0f}, 0.2f, 0);
    s.add_triangle({0, 0, 1}, {4, 0, 0.5f}, {0, 4, 0.2f}, 0);
    s.camera.from = {2, -3, 3};
    s.camera.at = {2, 2, 0};
    s.camera.up = {0, 0, 1};
    s.update_features();
    return s;
}

TEST(HeightField, EveryStructureMatchesBruteForce) {
    const Scene terrain = load_scene("gen:terrain:4"), mixed = mixed_scene();
    for (const Scene* scene : {&terrain, &mixed}) {
        ASSERT_TRUE(scene->features.height_fields);
        const BruteForce brute(*scene, KernelChoice{});
        std::mt19937 rng(13);
        std::vector<Rayf> rays = camera_rays(*scene, 48);
        for (const Rayf& r : random_rays(*scene, rng, 3000, 0.3f)) rays.push_back(r);
        const std::vector<Hitf> want = trace_hits(brute, rays);
        const std::vector<Rayf> shadows = shadow_rays(*scene, rays, want);
        const std::vector<std::uint8_t> want_occ = trace_occlusion(brute, shadows);
        int hits_on_fields = 0;
        for (const Hitf& h : want) hits_on_fields += h.found() && scene->prims[h.prim].kind == PrimKind::HeightField;
        EXPECT_GT(hits_on_fields, 500);
        for (const char* kind : {"bvh2", "bvh4", "bvh8", "grid", "kdtree", "octree"}) {
            AccelConfig config;
            config.kind = kind;
            const std::unique_ptr<Accel> accel = build_accel(*scene, config);
            for (int width : {1, 4, 8, 16}) {
                if (!accel->supports_packet(width)) continue;
                const Mismatches m = compare_hits(*scene, rays, want, trace_hits(*accel, rays, width), 3);
                EXPECT_EQ(m.count, 0u) << kind << " width " << width << ": " << m.first;
                const Mismatches o =
                    compare_occluded(*scene, KernelChoice{}, shadows, want_occ, trace_occlusion(*accel, shadows, width), 3);
                EXPECT_EQ(o.count, 0u) << kind << " width " << width << " shadows: " << o.first;
            }
        }
    }
}

Scene parse(const std::string& text) { return load_nff_text(text, "test.nff"); }

TEST(HeightField, InlineSyntaxMapsHeightsToZRange) {
    const Scene s = parse("f 1 1 1 1 0 0 0 1\nhf 3 2 0 0 -1 2 1 3\n0 0.5 1\n0.25 0.75 1\ns 0 0 0 1\n");
    ASSERT_EQ(s.height_fields.size(), 1u);
    ASSERT_EQ(s.primitive_count(), 2u);
    EXPECT_EQ(s.prims[0].kind, PrimKind::HeightField);
    const HeightField& f = s.height_fields[0];
    EXPECT_EQ(f.nx, 3u);
    EXPECT_EQ(f.ny, 2u);
    // z = -1 + h * 4, row y0 first.
    EXPECT_EQ(f.sample(0, 0), -1.0f);
    EXPECT_EQ(f.sample(1, 0), 1.0f);
    EXPECT_EQ(f.sample(2, 1), 3.0f);
    EXPECT_EQ(f.sample(0, 1), 0.0f);
    EXPECT_EQ(f.lo.z, -1.0f);  // the box: the lowest and highest sample
    EXPECT_EQ(f.hi.z, 3.0f);
    EXPECT_TRUE(s.features.height_fields);
}

TEST(HeightField, BadInputIsAClearError) {
    const BadScene cases[] = {
        {"hf 1 4 0 0 0 1 1 1\n0 0 0 0\n", 1, "sample count 1 outside [2, 65536]"},
        {"hf 3 70000 0 0 0 1 1 1\n", 1, "sample count 70000 outside"},
        {"hf 20000 20000 0 0 0 1 1 1\n", 1, "exceeds the limit of 268435456"},
        {"hf 2 2 0 0 0 0 1 1\n0 0 0 0\n", 1, "rectangle is empty"},
        {"hf 2 2 0 0 0 1 1 1\n0 0 0\n", 2, "unexpected end of file: expected height"},
        {"hf 2 2 0 0 0 1 1 1\n0 0\nx 0\n", 3, "expected a number for height"},
        {"hf 2 2 0 0 0 1 1 1\n0 nan 0 0\n", 2, "non-finite number 'nan' for height"},
        {"hf 2 2 0 0 -3e38 1 1 3e38\n0 0 1 1\n", 1, "height field height overflows"},
        {"hf 99999999999999999999 2 0 0 0 1 1 1\n", 1, "out of range"},
        {"hf missing.png 0 0 0 1 1 1\n", 1, "hf 'missing.png'"},
    };
    expect_scene_errors(cases);
}

TEST(HeightField, ImageFormReadsTheFirstChannelTopRowAtY1) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "raypack_test_height_field";
    std::filesystem::create_directories(dir);
    Image image(4, 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x) image.set(x, y, {float(x + 4 * y) / 255.0f, 1.0f, 0.0f});
    write_image((dir / "height.png").string(), image);
    set_height_image_reader([](const std::string& path, std::uint32_t& w, std::uint32_t& h) {
        const Image im = read_image(path);
        w = std::uint32_t(im.width);
        h = std::uint32_t(im.height);
        std::vector<float> first(std::size_t(w) * h);
        for (std::size_t p = 0; p < first.size(); ++p) first[p] = im.rgb[p * 3];
        return first;
    });
    const std::string nff = (dir / "field.nff").string();
    {
        std::ofstream out(nff);
        out << "hf height.png 0 0 0 3 2 255\n";  // relative to the NFF file's folder
    }
    const Scene s = load_scene(nff);
    ASSERT_EQ(s.height_fields.size(), 1u);
    const HeightField& f = s.height_fields[0];
    ASSERT_EQ(f.nx, 4u);
    ASSERT_EQ(f.ny, 3u);
    // Pixel (x, y) has value x + 4 y (8 bits, written through libpng); the
    // image's top row is the field's last (y1).
    for (std::uint32_t j = 0; j < 3; ++j)
        for (std::uint32_t i = 0; i < 4; ++i) EXPECT_NEAR(f.sample(i, j), float(i + 4 * (2 - j)), 1e-3f) << i << " " << j;
    std::filesystem::remove_all(dir);
}

TEST(HeightField, TerrainIsMountsMountain) {
    // gen terrain is gen mount's mountain as one field: as triangles, the
    // same vertices (to the 6 digits both print) and as many triangles.
    for (int size : {2, 4}) {
        const Scene terrain = height_fields_as_triangles(load_scene("gen:terrain:" + std::to_string(size)));
        const Scene mount = load_scene("gen:mount:" + std::to_string(size));
        ASSERT_EQ(terrain.triangles.size(), mount.triangles.size());
        auto sorted_vertices = [](const Scene& s) {
            std::vector<std::array<float, 3>> v;
            for (std::size_t i = 0; i < s.triangles.size(); ++i)
                for (const Vec3f& p : {s.triangles.p0[i], s.triangles.p1[i], s.triangles.p2[i]})
                    v.push_back({p.x, p.y, p.z});
            std::sort(v.begin(), v.end());
            v.erase(std::unique(v.begin(), v.end()), v.end());
            return v;
        };
        const auto a = sorted_vertices(terrain), b = sorted_vertices(mount);
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t k = 0; k < a.size(); ++k)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[k][c], b[k][c], 1e-6f) << size << " vertex " << k;
        EXPECT_EQ(terrain.spheres.size(), mount.spheres.size());
    }
}

}  // namespace
}  // namespace raypack
