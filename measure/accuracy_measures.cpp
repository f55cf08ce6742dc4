#include "measure/accuracy_measures.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <random>

#include "accel/brute/brute_force.h"
#include "measure/ray_sets.h"
#include "render/camera_rays.h"
#include "render/sampling.h"
#include "render/surface.h"

namespace raypack {
namespace {

constexpr std::size_t kBlock = 4096;  // rays per parallel task, each with its own generator

/// The generator of block `b`: the rays depend on (seed, block) alone.
std::mt19937_64 block_generator(std::uint64_t seed, std::size_t block) {
    std::seed_seq seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(block), std::uint32_t(block >> 32)};
    return std::mt19937_64(seq);
}

Vec3f to_float(const Vec3d& v) { return {float(v.x), float(v.y), float(v.z)}; }

/// Runs `body(begin, end, generator)` over [0, count) in blocks, in parallel.
template <class Body>
void for_blocks(std::uint64_t count, std::uint64_t seed, const Body& body) {
    const std::size_t blocks = std::size_t((count + kBlock - 1) / kBlock);
    tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
        std::mt19937_64 g = block_generator(seed, b);
        const std::uint64_t begin = std::uint64_t(b) * kBlock;
        body(begin, std::min<std::uint64_t>(count, begin + kBlock), g);
    });
}

void add(std::atomic<std::uint64_t>& a, std::uint64_t v) { a.fetch_add(v, std::memory_order_relaxed); }

/// Leak counters shared by the blocks of one measure.
struct AtomicLeaks {
    std::atomic<std::uint64_t> vertex_rays{0}, vertex_leaks{0}, edge_rays{0}, edge_leaks{0}, inside_rays{0},
        inside_leaks{0};
    void add_block(const LeakCounts& c) {
        add(vertex_rays, c.vertex_rays), add(vertex_leaks, c.vertex_leaks), add(edge_rays, c.edge_rays);
        add(edge_leaks, c.edge_leaks), add(inside_rays, c.inside_rays), add(inside_leaks, c.inside_leaks);
    }
    LeakCounts get() const {
        return {vertex_rays, vertex_leaks, edge_rays, edge_leaks, inside_rays, inside_leaks};
    }
};

/// The triangles of each closed mesh and its size (largest distance from the centroid to a vertex).
struct MeshIndex {
    std::vector<std::vector<std::uint32_t>> triangles;  ///< per object with triangles
    std::vector<std::uint32_t> object;                   ///< the object of each entry
    std::vector<float> size;
    std::vector<std::uint32_t> all;                      ///< every triangle of every mesh
};

MeshIndex index_meshes(const ObjectScene& meshes) {
    std::vector<std::vector<std::uint32_t>> by_object(meshes.object_count());
    for (std::uint32_t prim = 0; prim < meshes.scene.primitive_count(); ++prim)
        if (meshes.scene.prims[prim].kind == PrimKind::Triangle) by_object[meshes.object[prim]].push_back(prim);
    MeshIndex index;
    const TriangleSoA& t = meshes.scene.triangles;
    for (std::uint32_t o = 0; o < by_object.size(); ++o) {
        if (by_object[o].size() < 4) continue;  // not a closed mesh
        float size = 0;
        for (std::uint32_t prim : by_object[o]) {
            const std::uint32_t i = meshes.scene.prims[prim].index;
            for (const Vec3f& p : {t.p0[i], t.p1[i], t.p2[i]}) size = std::max(size, length(p - meshes.centroid[o]));
            index.all.push_back(prim);
        }
        index.triangles.push_back(by_object[o]);
        index.object.push_back(o);
        index.size.push_back(size);
    }
    return index;
}

/// Position of `f` on the number line of floats: neighbours differ by 1.
std::int64_t ordered_bits(float f) {
    const auto bits = std::int64_t(std::bit_cast<std::int32_t>(f));
    return bits < 0 ? std::int64_t(std::numeric_limits<std::int32_t>::min()) - bits : bits;
}

double percentile(const std::vector<double>& sorted, double q) {
    if (sorted.empty()) return 0;
    return sorted[std::min(sorted.size() - 1, std::size_t(q * double(sorted.size() - 1) + 0.5))];
}

/// The reference kernels: watertight triangles, precise spheres.
constexpr KernelChoice kReferenceKernels{.sphere = SphereMethod::Precise, .triangle = TriangleMethod::Watertight};

/// Every intersection by the brute-force oracle in double precision.
class DoubleOracle final : public Accel {
public:
    explicit DoubleOracle(const Scene& scene) : brute_(scene, kReferenceKernels) { stats_.name = "brute-double"; }
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override {
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Rayf& r = rays[i];
            const Hit<double> h = brute_.intersect_double(Ray<double>{Vec3d(r.org), Vec3d(r.dir), r.tnear, r.tfar});
            hits[i] = h.found() ? Hitf{float(h.t), h.prim, float(h.u), float(h.v)} : Hitf{};
        }
    }
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override {
        std::vector<Hitf> hits(rays.size());
        intersect(rays, hits);
        for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = hits[i].found() ? 1 : 0;
    }

private:
    BruteForce brute_;
};

}  // namespace

LeakCounts count_mesh_leaks(const ObjectScene& meshes, const Accel& accel, std::uint64_t ray_count,
                            std::uint64_t seed) {
    const MeshIndex index = index_meshes(meshes);
    if (index.triangles.empty()) return {};
    const TriangleSoA& tri = meshes.scene.triangles;
    AtomicLeaks total;
    for_blocks(ray_count, seed, [&](std::uint64_t begin, std::uint64_t end, std::mt19937_64& g) {
        enum Aim : std::uint8_t { Vertex, Edge, Inside };
        std::vector<Rayf> rays;
        std::vector<Aim> aims;
        std::vector<float> limits;  // a hit must come before this t
        for (std::uint64_t r = begin; r < end; ++r) {
            // Half the rays pick a mesh first (so the many small tetrahedra
            // count), half a triangle first (so the fine spheres count).
            std::size_t m;
            std::uint32_t prim;
            if (g() & 1) {
                m = std::size_t(g() % index.triangles.size());
                prim = index.triangles[m][std::size_t(g() % index.triangles[m].size())];
            } else {
                prim = index.all[std::size_t(g() % index.all.size())];
                m = std::size_t(std::lower_bound(index.object.begin(), index.object.end(),
                                                 meshes.object[prim]) - index.object.begin());
            }
            const std::uint32_t i = meshes.scene.prims[prim].index;
            const Vec3f corner[3] = {tri.p0[i], tri.p1[i], tri.p2[i]};
            const int k = int(g() % 3);
            const Aim aim = (g() & 3) == 0 ? Inside : (g() & 1) ? Vertex : Edge;
            const bool at_vertex = aim == Vertex || (aim == Inside && (g() & 1));
            const Vec3f target = at_vertex ? corner[k]
                                           : corner[k] + (corner[(k + 1) % 3] - corner[k]) * float(uniform(g, 0.001, 0.999));
            // An interior point: the centroid moved by up to a fifth of the
            // mesh's size (the meshes are convex and at least that thick).
            const Vec3f inner = meshes.centroid[index.object[m]] +
                                to_float(uniform_sphere(g)) * (index.size[m] * float(uniform(g, 0, 0.2)));
            Rayf ray;
            if (aim == Inside) {
                ray.org = inner;
                limits.push_back(1.001f);
            } else {
                // From beyond the target on the line from `inner`: the ray
                // meets the surface at the target and goes on toward `inner`,
                // which it reaches at t = 1 + 1/k.
                const float beyond = float(uniform(g, 1, 3));
                ray.org = target + (target - inner) * beyond;
                limits.push_back(1.0f + 0.5f / beyond);
            }
            ray.dir = target - ray.org;
            rays.push_back(ray);
            aims.push_back(aim);
        }
        std::vector<Hitf> hits(rays.size());
        accel.intersect(rays, hits);
        LeakCounts local;
        for (std::size_t r = 0; r < rays.size(); ++r) {
            const bool leak = !hits[r].found() || hits[r].t > limits[r];
            switch (aims[r]) {
                case Vertex: ++local.vertex_rays, local.vertex_leaks += leak; break;
                case Edge: ++local.edge_rays, local.edge_leaks += leak; break;
                case Inside: ++local.inside_rays, local.inside_leaks += leak; break;
            }
        }
        total.add_block(local);
    });
    return total.get();
}

ObjectScene leak_test_spheres() {
    Scene scene;
    scene.materials.push_back(Material{});
    const Vec3f centres[] = {{0, 0, 0}, {100, -30, 7}, {1e4f, 2e3f, -5e3f}};
    for (const Vec3f& c : centres)
        for (int k = -3; k <= 3; ++k) scene.add_sphere(c + Vec3f{0, 0, 3.0f * std::pow(10.0f, float(k))}, std::pow(10.0f, float(k)), 0);
    scene.update_features();
    return group_into_objects(std::move(scene));
}

LeakCounts count_sphere_leaks(const ObjectScene& spheres, const Accel& accel, std::uint64_t ray_count,
                              std::uint64_t seed) {
    const SphereSoA& s = spheres.scene.spheres;
    if (s.size() == 0) return {};
    AtomicLeaks total;
    for_blocks(ray_count, seed, [&](std::uint64_t begin, std::uint64_t end, std::mt19937_64& g) {
        std::vector<Rayf> rays;
        for (std::uint64_t r = begin; r < end; ++r) {
            const std::size_t i = std::size_t(g() % s.size());
            const Vec3d c(s.center[i]);
            const double radius = s.radius[i];
            // Inside by the float values themselves (checked in double): a
            // point rounded onto or past the surface is drawn again.
            Vec3f org = s.center[i];
            for (int attempt = 0; attempt < 8; ++attempt) {
                const double depth = std::ldexp(1.0, -int(uniform(g, 1, 21)));
                const Vec3f candidate = to_float(c + uniform_sphere(g) * (radius * (1 - depth)));
                if (length(Vec3d(candidate) - c) < radius) {
                    org = candidate;
                    break;
                }
            }
            Rayf ray;
            ray.org = org;
            ray.dir = to_float(uniform_sphere(g));
            rays.push_back(ray);
        }
        std::vector<Hitf> hits(rays.size());
        accel.intersect(rays, hits);
        LeakCounts local;
        local.inside_rays = rays.size();
        for (const Hitf& h : hits) local.inside_leaks += !h.found();
        total.add_block(local);
    });
    return total.get();
}

UlpError t_error_ulps(const Scene& scene, PrimKind kind, KernelChoice kernels, std::uint64_t ray_count,
                      std::uint64_t seed) {
    std::vector<std::uint32_t> prims;
    for (std::uint32_t p = 0; p < scene.primitive_count(); ++p)
        if (scene.prims[p].kind == kind) prims.push_back(p);
    if (prims.empty()) return {};
    const PrimitiveIntersector<float> tested{&scene, kernels};
    const PrimitiveIntersector<double> reference{&scene, kReferenceKernels};
    std::vector<double> ulps;
    std::atomic<std::uint64_t> missed{0};
    std::mutex merge;
    for_blocks(ray_count, seed, [&](std::uint64_t begin, std::uint64_t end, std::mt19937_64& g) {
        std::vector<double> local;
        std::uint64_t local_missed = 0;
        for (std::uint64_t r = begin; r < end; ++r) {
            const std::uint32_t prim = prims[std::size_t(g() % prims.size())];
            const std::uint32_t i = scene.prims[prim].index;
            Vec3d target, centre;
            double size;
            if (kind == PrimKind::Triangle) {
                const Vec3d a(scene.triangles.p0[i]), b(scene.triangles.p1[i]), c(scene.triangles.p2[i]);
                double u = uniform(g), v = uniform(g);
                if (u + v > 1) u = 1 - u, v = 1 - v;
                target = a * (1 - u - v) + b * u + c * v;
                centre = (a + b + c) * (1.0 / 3);
                size = std::max({length(a - centre), length(b - centre), length(c - centre)});
            } else {
                centre = Vec3d(scene.spheres.center[i]);
                size = scene.spheres.radius[i];
                target = centre;
            }
            const Vec3d w = uniform_sphere(g);
            const Vec3d org = target + w * (size * std::pow(10.0, uniform(g, std::log10(2.0), 4)));
            if (kind == PrimKind::Sphere) {
                // A point of the disc the sphere shows toward the origin.
                Vec3d d = uniform_sphere(g);
                d = d - w * dot(d, w);
                if (length(d) > 0) target = centre + d * (size * 0.99 * std::sqrt(uniform(g)) / length(d));
            }
            Rayf ray;
            ray.org = to_float(org);
            ray.dir = to_float(target - Vec3d(ray.org));
            Ray<double> ray_d{Vec3d(ray.org), Vec3d(ray.dir), 0, std::numeric_limits<double>::infinity()};
            Hitf hit;
            Hit<double> hit_d;
            if (!reference.intersect(prim, ray_d, hit_d)) continue;
            if (!tested.intersect(prim, ray, hit)) {
                ++local_missed;
                continue;
            }
            local.push_back(double(std::llabs(ordered_bits(hit.t) - ordered_bits(float(hit_d.t)))));
        }
        add(missed, local_missed);
        const std::lock_guard lock(merge);
        ulps.insert(ulps.end(), local.begin(), local.end());
    });
    std::sort(ulps.begin(), ulps.end());
    UlpError e;
    e.rays = ulps.size();
    e.missed = missed;
    e.median = percentile(ulps, 0.5);
    e.p99 = percentile(ulps, 0.99);
    e.max = ulps.empty() ? 0 : ulps.back();
    return e;
}

SelfIntersections count_self_intersections(const ObjectScene& objects, const Accel& accel, OffsetPolicy policy,
                                           int width, int height) {
    const Scene& scene = objects.scene;
    const std::vector<Rayf> camera = camera_ray_set(scene, width, height);
    std::vector<Hitf> hits(camera.size());
    accel.intersect(camera, hits);
    const RayOffset offset(policy, scene);
    const Vec3f light = scene.lights.empty() ? Vec3f{} : scene.lights.front().position;
    std::vector<Rayf> shadow, reflect, shadow_reference;
    std::vector<std::uint32_t> shadow_from, reflect_from;
    for (std::size_t i = 0; i < camera.size(); ++i) {
        if (!hits[i].found()) continue;
        const Surface s = surface_at(scene, camera[i], hits[i]);
        const Vec3f n = dot(s.geometric_normal, camera[i].dir) < 0 ? s.geometric_normal : -s.geometric_normal;
        const std::uint32_t object = objects.object[hits[i].prim];
        // Only hits on the outside: a camera ray through a crack sees the inside.
        if (dot(n, s.point - objects.centroid[object]) <= 0) continue;
        const Vec3f p = offset.hit_point(scene, camera[i], hits[i], s.point);
        const Vec3f org = offset.offset(p, n);
        Rayf r;
        r.org = org;
        r.tnear = offset.tnear();
        const Vec3f view = normalize(camera[i].dir);
        r.dir = view - n * (2.0f * dot(view, n));
        reflect.push_back(r);
        reflect_from.push_back(object);
        if (!scene.lights.empty() && dot(n, light - p) > 0) {
            r.dir = light - org;
            r.tfar = 1.0f - 1e-6f;
            shadow.push_back(r);
            shadow_from.push_back(object);
            Rayf exact;
            exact.org = accurate_hit_point(scene, camera[i], hits[i]);
            exact.dir = light - exact.org;
            exact.tfar = r.tfar;
            shadow_reference.push_back(exact);
        }
    }
    auto closest = [&](const std::vector<Rayf>& rays) {
        std::vector<Hitf> h(rays.size());
        tbb::parallel_for(std::size_t(0), rays.size(), kBlock, [&](std::size_t b) {
            const std::size_t n = std::min(kBlock, rays.size() - b);
            accel.intersect({rays.data() + b, n}, {h.data() + b, n});
        });
        return h;
    };
    auto count_self = [&](const std::vector<Hitf>& h, const std::vector<std::uint32_t>& from) {
        std::uint64_t self = 0;
        for (std::size_t i = 0; i < h.size(); ++i) self += h[i].found() && objects.object[h[i].prim] == from[i];
        return self;
    };
    SelfIntersections out;
    const std::vector<Hitf> shadow_hits = closest(shadow);
    out.shadow_rays = shadow.size();
    out.shadow_self = count_self(shadow_hits, shadow_from);
    out.reflect_rays = reflect.size();
    out.reflect_self = count_self(closest(reflect), reflect_from);
    // The reference: step past the object left (a convex object meets a ray
    // leaving it outward only at its origin, up to rounding).
    std::vector<Hitf> reference = closest(shadow_reference);
    for (int step = 0; step < 4; ++step) {
        std::vector<std::size_t> again;
        for (std::size_t i = 0; i < reference.size(); ++i)
            if (reference[i].found() && objects.object[reference[i].prim] == shadow_from[i]) again.push_back(i);
        if (again.empty()) break;
        std::vector<Rayf> rays;
        for (std::size_t i : again) {
            rays.push_back(shadow_reference[i]);
            rays.back().tnear = std::nextafter(reference[i].t, std::numeric_limits<float>::infinity());
        }
        const std::vector<Hitf> next = closest(rays);
        for (std::size_t k = 0; k < again.size(); ++k) reference[again[k]] = next[k];
    }
    for (std::size_t i = 0; i < shadow.size(); ++i) {
        const bool reference_occluded = reference[i].found() && objects.object[reference[i].prim] != shadow_from[i];
        out.shadow_wrong += shadow_hits[i].found() != reference_occluded;
    }
    return out;
}

Image render_double_reference(const Scene& scene, const WhittedOptions& options) {
    const DoubleOracle oracle(scene);
    WhittedOptions single = options;
    single.packet = 1;
    Image image;
    render_whitted(scene, oracle, single, image);
    return image;
}

ImageError image_error(const Image& test, const Image& reference) {
    ImageError e;
    if (test.rgb.size() != reference.rgb.size() || test.rgb.empty()) return {0, 1};
    double squared = 0;
    std::size_t differing = 0;
    for (std::size_t p = 0; p < test.rgb.size(); p += 3) {
        bool differs = false;
        for (std::size_t c = 0; c < 3; ++c) {
            const double d = std::clamp(double(test.rgb[p + c]), 0.0, 1.0) - std::clamp(double(reference.rgb[p + c]), 0.0, 1.0);
            squared += d * d;
            differs |= std::fabs(d) > 1.0 / 255;
        }
        differing += differs;
    }
    const double mse = squared / double(test.rgb.size());
    e.psnr_db = mse > 0 ? 10 * std::log10(1 / mse) : std::numeric_limits<double>::infinity();
    e.differing_fraction = double(differing) / double(test.rgb.size() / 3);
    return e;
}

}  // namespace raypack
