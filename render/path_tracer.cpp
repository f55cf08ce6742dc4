#include "render/path_tracer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

#include "render/append_buffer.h"
#include "render/camera_rays.h"
#include "render/camera_samples.h"
#include "render/film.h"
#include "render/light_sampling.h"
#include "render/ray_coherence.h"
#include "render/ray_offset.h"
#include "render/sampler.h"
#include "render/sampling.h"
#include "render/shade_lanes.h"
#include "render/sin_cos_turns.h"
#include "render/surface.h"
#include "render/surface_lanes.h"
#include "render/thin_lens.h"
#include "render/tiles.h"

namespace raypack {
namespace {

constexpr float kInvPi = std::numbers::inv_pi_v<float>;
/// Paths per batch of a tile, at most (and at least one sample per pixel).
constexpr std::size_t kMaxBatch = 16384;

float max_component(const Vec3f& v) { return std::max({v.x, v.y, v.z}); }

/// The live paths of one tile: their next ray, what they carry, and where
/// their radiance goes.
struct Paths {
    // Append buffers, not vectors: a new path's entries are written once,
    // by the caller, where a vector's resize or emplace_back would
    // value-initialise them first (rays and hits, which the camera and the
    // structure overwrite whole, were 6% of the bunny's path render).
    AppendBuffer<Rayf> rays;
    AppendBuffer<Hitf> hits;  ///< written by the structure's query
    AppendBuffer<Vec3f> throughput;
    AppendBuffer<std::uint32_t> sample;  ///< index into the tile's samples (radiance, sampler key)
    AppendBuffer<std::uint8_t> count_emission;  ///< camera ray, or after a specular bounce
    /// After a diffuse bounce: its direction's density (solid angle) and
    /// origin, for the MIS weight of emission the ray finds.
    AppendBuffer<float> bounce_pdf;
    AppendBuffer<Vec3f> bounce_origin;  ///< read only where bounce_pdf > 0

    void clear() {
        rays.clear();
        hits.clear();
        throughput.clear();
        sample.clear();
        count_emission.clear();
        bounce_pdf.clear();
        bounce_origin.clear();
    }
    /// n camera paths, sample i in path i; the caller writes their rays.
    /// Whole arrays at once rather than a push_back per field and path
    /// (with the film change beside it: the bunny's render 5% faster).
    void start_camera_paths(std::size_t n) {
        rays.resize_for_overwrite(n);
        hits.resize_for_overwrite(n);
        bounce_origin.resize_for_overwrite(n);
        std::fill_n(throughput.resize_for_overwrite(n), n, Vec3f{1, 1, 1});
        std::uint32_t* samples = sample.resize_for_overwrite(n);
        for (std::size_t i = 0; i < n; ++i) samples[i] = std::uint32_t(i);
        std::fill_n(count_emission.resize_for_overwrite(n), n, std::uint8_t(1));
        std::fill_n(bounce_pdf.resize_for_overwrite(n), n, 0.0f);
    }
    /// Room for n more paths, for append_reserved() (the arrays grow
    /// together, here and in start_camera_paths).
    void reserve_more(std::size_t n) {
        reserve_together(rays.size() + n, rays, hits, throughput, sample, count_emission, bounce_pdf, bounce_origin);
    }
    /// One more path within reserve_more()'s room, every entry but its hit
    /// left for the caller to write (a Rayf built on the stack and copied
    /// stalls on store forwarding: 13% of a path-traced Cornell box);
    /// returns its index.
    RAYPACK_INLINE std::size_t append_reserved() {
        return append_together(rays, hits, throughput, sample, count_emission, bounce_pdf, bounce_origin);
    }
    /// A new path whose ray the caller writes in place. `origin`: where a
    /// diffuse bounce left (read only when pdf > 0).
    Rayf& add(const Vec3f& beta, std::uint32_t s, bool emission, float pdf = 0, const Vec3f& origin = {}) {
        reserve_more(1);
        const std::size_t k = append_reserved();
        throughput[k] = beta;
        sample[k] = s;
        count_emission[k] = emission;
        bounce_pdf[k] = pdf;
        bounce_origin[k] = origin;
        return rays[k];
    }
};

struct Shadows {
    AppendBuffer<Rayf> rays;
    AppendBuffer<std::uint32_t> sample;
    AppendBuffer<Vec3f> contribution;
    AppendBuffer<std::uint8_t> occluded;  ///< written by the structure's query
    void clear() {
        rays.clear();
        sample.clear();
        contribution.clear();
    }
    /// Room for n more shadow rays, for append_reserved().
    void reserve_more(std::size_t n) { reserve_together(rays.size() + n, rays, sample, contribution); }
    /// One more shadow ray within reserve_more()'s room, for the caller to
    /// write; returns its index.
    RAYPACK_INLINE std::size_t append_reserved() { return append_together(rays, sample, contribution); }
};

/// A camera sample: its pixel (with the pixel's part of the sampler's hash,
/// computed once) and its index in the pixel.
using SampleKey = Sampler::Draw;

struct Scratch {
    std::vector<PixelXY> pixels;
    CameraSampleBatch camera;  ///< the batch's camera samples; camera.keys: per sample of the batch
    /// The draws of one bounce for the paths that found a surface: what the
    /// path's sample draws in the bounce's four dimensions (choice and
    /// roulette, light, point on the light, direction), in bounce_draws[d]
    /// at the path's draw_of entry.
    std::vector<SampleKey> bounce_keys;
    std::vector<std::int32_t> draw_of;
    std::vector<std::uint32_t> found;  ///< the level's paths that found a surface (draw_bounce)
    std::vector<Sample2> bounce_draws[4];
    std::vector<Vec3f> radiance;      ///< per sample of the tile
    std::vector<float> times;         ///< moving scenes: per ray of a query, its sample's time
    Paths paths, next;
    Shadows shadows;
    RenderStats stats;
};

class PathTracer {
public:
    PathTracer(const Scene& scene, const Accel& accel, const WhittedOptions& options, const PathOptions& path)
        : scene_(scene),
          accel_(accel),
          options_(options),
          path_(path),
          offset_(options.offset, scene),
          surfaces_(scene),
          samples_(options.sampler, options.spp, options.seed),
          timed_(!scene.moving_instances.empty()),
          // Vertices in SIMD lanes need the Epsilon or Scaled offset (the
          // robust one reads the primitive) and a static scene.
          lanes_(path.lanes && !timed_ && options.offset != OffsetPolicy::Robust && kShadeLanes > 1),
          black_background_(scene.background.x == 0 && scene.background.y == 0 && scene.background.z == 0),
          // A ray of depth max_depth only gathers emission: area lights'
          // surfaces, or the background where it misses.
          spawn_below_(path.skip_dark_rays && scene.area_lights.empty() && black_background_ ? path.max_depth - 1
                                                                                            : path.max_depth) {
        parts_.reserve(scene.materials.size());
        for (const Material& m : scene.materials) {
            MaterialParts q;
            q.albedo = m.color * m.kd;
            q.wd = std::max(0.0f, max_component(q.albedo));
            q.ws = std::max(0.0f, m.ks);
            q.wt = std::max(0.0f, m.transmittance);
            q.total = q.wd + q.ws + q.wt;
            q.mirror_weight = (Vec3f{1, 1, 1} * (q.total / q.ws) * m.ks).x;
            q.mirror = !(m.gloss > 0);
            parts_.push_back(q);
        }
        for (const AreaLight& light : scene.area_lights) parallelograms_.push_back(sample_area_light(light, {}, {}));
    }

    const Sampler& samples() const { return samples_; }

    /// Traces the paths whose camera rays are s.paths (one per sample of
    /// the tile), adding their radiance to s.radiance.
    void trace(Scratch& s) const {
        s.stats.eye_rays += s.paths.rays.size();
        for (int depth = 1; !s.paths.rays.empty(); ++depth) {
            Paths& p = s.paths;
            const int width = depth == 1 ? options_.packet : options_.secondary_packet;
            const auto times = timed_ ? times_of(p.sample, s) : std::span<const float>{};
            if (options_.ray_log) options_.ray_log->add(depth == 1 ? RayLog::Eye : RayLog::Bounce, p.rays, times);
            // Bounces off diffuse and glossy surfaces go every which way:
            // as one stream (the bunny 1.15x faster; their shadow rays
            // as a stream too were no faster).
            if (timed_) accel_.intersect_at(width, p.rays, times, p.hits);
            else if (depth > 1 && accel_.supports_stream() && incoherent(p.rays))
                accel_.intersect_stream(width, p.rays, p.hits);
            else accel_.intersect_packets(width, p.rays, p.hits);
            if (depth == 1)
                for (const Hitf& h : p.hits) s.stats.eye_hits += h.found();
            s.next.clear();
            s.shadows.clear();
            if (depth < path_.max_depth) draw_bounce(depth, s);
            if (lanes_ && depth < path_.max_depth) {
                // The paths that found a surface (draw_bounce's list) fill
                // the lanes: a bunny's camera rays hit in 3 of 10 lanes. A
                // miss only adds the background, as bounce() does.
                if (!black_background_)
                    for (std::size_t i = 0; i < p.rays.size(); ++i)
                        if (!p.hits[i].found()) s.radiance[p.sample[i]] += p.throughput[i] * scene_.background;
                for (std::size_t k = 0; k < s.found.size(); k += kShadeLanes)
                    bounce_lanes(std::span<const std::uint32_t>(s.found).subspan(
                                     k, std::min<std::size_t>(kShadeLanes, s.found.size() - k)),
                                 depth, s);
            } else
                for (std::size_t i = 0; i < p.rays.size(); ++i) bounce(i, depth, s);
            trace_shadows(s);
            std::swap(s.paths, s.next);
        }
    }

private:
    const Scene& scene_;
    const Accel& accel_;
    const WhittedOptions& options_;
    const PathOptions& path_;
    RayOffset offset_;
    SurfaceTable surfaces_;
    Sampler samples_;
    bool timed_;  ///< the scene moves: every ray at its camera sample's time
    bool lanes_;  ///< diffuse vertices in SIMD lanes (bounce_lanes)
    bool black_background_;  ///< a miss adds nothing
    /// Vertices of depth below this spawn the next ray (PathOptions::skip_dark_rays).
    int spawn_below_;
    /// Per material, bounce's weights of its diffuse, specular and
    /// transmitting parts (computed as bounce computes them).
    struct MaterialParts {
        Vec3f albedo;
        float wd, ws, wt, total;
        float mirror_weight;  ///< a mirror bounce's weight, (total / ws) ks
        bool mirror;          ///< its specular part is a perfect mirror (no gloss)
    };
    std::vector<MaterialParts> parts_;
    /// Per area light: a parallelogram's normal and density, which
    /// sample_area_light computes for every sample (three divisions).
    std::vector<LightSample> parallelograms_;

    /// The times of rays whose samples are `samples` (indices into the batch).
    static std::span<const float> times_of(std::span<const std::uint32_t> samples, Scratch& s) {
        s.times.resize(samples.size());
        for (std::size_t k = 0; k < samples.size(); ++k) s.times[k] = s.camera.time[samples[k]];
        return s.times;
    }

    /// Dimensions of the bounce at `depth`: part choice and roulette, light
    /// choice, point on the light, direction of the bounce.
    static int first_dimension(int depth) { return 2 + 4 * (depth - 1); }

    /// The bounce's draws for every path that found a surface, all at once
    /// (Sampler::get_many); the point on a light only if there are area lights.
    void draw_bounce(int depth, Scratch& s) const {
        const Paths& p = s.paths;
        s.bounce_keys.clear();
        s.found.clear();
        s.draw_of.resize(p.rays.size());
        for (std::size_t i = 0; i < p.rays.size(); ++i) {
            s.draw_of[i] = p.hits[i].found() ? std::int32_t(s.bounce_keys.size()) : -1;
            if (p.hits[i].found()) {
                s.bounce_keys.push_back(s.camera.keys[p.sample[i]]);
                s.found.push_back(std::uint32_t(i));
            }
        }
        const int dim = first_dimension(depth);
        for (int d = 0; d < 4; ++d) {
            if (d == 2 && scene_.area_lights.empty()) continue;
            if (d == 3 && depth >= spawn_below_) continue;
            s.bounce_draws[d].resize(s.bounce_keys.size());
            samples_.get_many(s.bounce_keys, dim + d, s.bounce_draws[d].data());
        }
    }

    /// Draw d of this bounce for path i (see Scratch::bounce_draws).
    static Sample2 drawn(const Scratch& s, std::size_t i, int d) {
        return s.bounce_draws[d][std::size_t(s.draw_of[i])];
    }

    void bounce(std::size_t i, int depth, Scratch& s) const {
        const Paths& p = s.paths;
        const Rayf ray = p.rays[i];
        const Hitf hit = p.hits[i];
        const std::uint32_t si = p.sample[i];
        const Vec3f beta = p.throughput[i];
        Vec3f& L = s.radiance[si];
        if (!hit.found()) {
            L += beta * scene_.background;
            return;
        }
        const float time = timed_ ? s.camera.time[si] : -std::numeric_limits<float>::infinity();
        const Surface surf = surfaces_.at(ray, hit, time);
        const Material& m = scene_.materials[surf.material];
        const Vec3f wo = -normalize(ray.dir);
        const bool front = dot(wo, surf.geometric_normal) > 0;
        const Vec3f ng = front ? surf.geometric_normal : -surf.geometric_normal;
        Vec3f ns = front ? surf.shading_normal : -surf.shading_normal;
        if (dot(ns, ng) < 0) ns = ng;
        if (m.area_light >= 0) {
            if (p.count_emission[i]) {
                L += beta * emitted(m.area_light, surf.geometric_normal, wo);
            } else if (p.bounce_pdf[i] > 0) {
                // Found by a diffuse bounce that next-event estimation could
                // also have sampled: weight by the power heuristic (Veach 1997).
                const Vec3f d = surf.point - p.bounce_origin[i];
                const float cos_l = std::fabs(dot(surf.geometric_normal, normalize(d)));
                const float pdf_light =
                    light_choice_pdf() * area_light_pdf(scene_.area_lights[std::size_t(m.area_light)],
                                                        p.bounce_origin[i]) * dot(d, d) / std::max(cos_l, 1e-12f);
                L += beta * emitted(m.area_light, surf.geometric_normal, wo) *
                     power_heuristic(p.bounce_pdf[i], pdf_light);
            }
        }
        if (depth >= path_.max_depth) return;

        const Vec3f hp = offset_.hit_point(scene_, ray, hit, surf.point, time);
        const Vec3f above = offset_.offset(hp, ng);
        // Choose one of the material's three parts in proportion to its weight.
        const Vec3f albedo = m.color * m.kd;
        const float wd = std::max(0.0f, max_component(albedo)), ws = std::max(0.0f, m.ks),
                    wt = std::max(0.0f, m.transmittance), total = wd + ws + wt;
        if (!(total > 0)) return;
        const Sample2 choice = drawn(s, i, 0);
        const float pick = choice.x * total;
        const bool spawn = depth < spawn_below_;
        Vec3f dir;
        Vec3f weight;
        bool specular = true;
        float bounce_pdf = 0;
        Vec3f origin = above;
        std::uint64_t* counter = &s.stats.reflect_rays;  // the kind of the ray spawned
        if (pick < wd) {
            // Lambertian: next-event estimation, then a cosine-weighted bounce.
            const Vec3f f = albedo * kInvPi;
            direct_light(i, si, above, ns, ng, beta * (total / wd), f, s);
            if (!spawn) return;
            const Sample2 u = drawn(s, i, 3);
            const Vec3f local = cosine_hemisphere(u.x, u.y);
            dir = OrthonormalBasis<float>(ns).to_world(local);
            bounce_pdf = local.z * kInvPi;
            weight = albedo * (total / wd);  // f cos / pdf = albedo
            specular = false;
            counter = &s.stats.diffuse_rays;
        } else if (pick < wd + ws) {
            if (!spawn) return;
            const Vec3f mirror = ns * (2.0f * dot(wo, ns)) - wo;
            dir = mirror;
            if (m.gloss > 0) {
                // Normalised Phong lobe about the mirror direction, sampled
                // exactly: the weight is 1 wherever the lobe is above the surface.
                const Sample2 u = drawn(s, i, 3);
                dir = OrthonormalBasis<float>(normalize(mirror)).to_world(phong_lobe(m.gloss, u.x, u.y));
                if (dot(dir, ng) <= 0) return;  // absorbed under the surface
            }
            weight = Vec3f{1, 1, 1} * (total / ws) * m.ks;
        } else {
            if (!spawn) return;
            // Dielectric interface without Fresnel (NFF's T is the weight).
            const float eta = front ? 1.0f / m.ior : m.ior;
            const float cos_i = dot(wo, ns);
            const float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
            weight = Vec3f{1, 1, 1} * (total / wt) * m.transmittance;
            if (k >= 0) {
                dir = -wo * eta + ns * (eta * cos_i - std::sqrt(k));
                origin = offset_.offset(hp, -ng);
                counter = &s.stats.refract_rays;
            } else {
                dir = ns * (2.0f * dot(wo, ns)) - wo;  // total internal reflection
            }
        }
        Vec3f next_beta = beta * weight;
        // Russian roulette (Arvo and Kirk 1990): survive with probability q,
        // divide by it, so the estimate stays unbiased.
        if (depth > path_.rr_depth) {
            const float q = std::min(1.0f, max_component(next_beta));
            if (!(choice.y < q)) return;
            next_beta = next_beta / q;
        }
        if (!(max_component(next_beta) > 0)) return;
        ++*counter;
        spawn_ray(origin, dir, offset_, s.next.add(next_beta, si, specular, bounce_pdf, origin));
    }

    /// bounce() for `paths` (at most kShadeLanes, each of which found a
    /// surface), bit for bit: the diffuse and perfect-mirror vertices (the
    /// common cases) in SIMD lanes, with bounce's operations in bounce's
    /// order (FMA contraction is off); the others (lights' surfaces, glossy
    /// lobes, glass) one by one through bounce(). Rays and shadow rays are
    /// appended in the order of `paths`, as bounce() appends them. Needs
    /// depth < max_depth.
    void bounce_lanes(std::span<const std::uint32_t> paths, int depth, Scratch& s) const {
        constexpr int K = kShadeLanes;
        using F = vfloat<K>;
        const Paths& p = s.paths;
        const int n = int(paths.size());
        // The surfaces in lanes (lanes past the last path repeat it); per
        // lane, the diffuse vertices' albedo and part weights, throughput
        // and draws.
        using I = vint<K>;
        alignas(64) std::int32_t path_index[K], material[K];
        for (int l = 0; l < K; ++l) path_index[l] = std::int32_t(paths[std::size_t(l < n ? l : n - 1)]);
        SurfaceLanes<K> surf;
        surf.gather(surfaces_, p.rays.data(), p.hits.data(), I::load_aligned(path_index), (2u << (n - 1)) - 1);
        surf.material.store_aligned(material);
        alignas(64) float albedo[3][K], beta[3][K];
        alignas(64) float total[K], wd[K], mirror_weight[K], roulette[K], u1[K], u2[K];
        std::uint32_t diffuse = 0, mirror = 0, nothing_to_do = 0;
        const bool spawn = depth < spawn_below_;
        for (int l = 0; l < n; ++l) {
            const std::size_t i = paths[std::size_t(l)];
            const auto m = std::size_t(material[l]);
            if (scene_.materials[m].area_light >= 0) continue;
            const MaterialParts& q = parts_[m];
            const Sample2 choice = drawn(s, i, 0);
            if (!(q.total > 0)) continue;
            const float pick = choice.x * q.total;
            Sample2 u{};
            if (pick < q.wd) {
                diffuse |= 1u << l;
                if (spawn) u = drawn(s, i, 3);
            } else if (pick < q.wd + q.ws && q.mirror) {
                if (!spawn) {  // a mirror vertex only spawns its ray
                    nothing_to_do |= 1u << l;
                    continue;
                }
                mirror |= 1u << l;
            } else {
                continue;
            }
            const Vec3f b = p.throughput[i];
            for (int a = 0; a < 3; ++a) {
                albedo[a][l] = q.albedo[a];
                beta[a][l] = b[a];
            }
            total[l] = q.total;
            wd[l] = q.wd;
            mirror_weight[l] = q.mirror_weight;
            roulette[l] = choice.y;
            u1[l] = u.x;
            u2[l] = u.y;
        }
        // Paths outside the lanes (lights' surfaces, glossy lobes, glass).
        const auto one_by_one = [&](std::size_t i) { bounce(i, depth, s); };
        const std::uint32_t in_lanes = diffuse | mirror;
        if (in_lanes == 0) {
            for (int l = 0; l < n; ++l)
                if (!((nothing_to_do >> l) & 1u)) one_by_one(paths[std::size_t(l)]);
            return;
        }
        // Lanes that are not vertices of the lanes compute garbage that is
        // never read; fill them with a copy of one that is, so that nothing
        // traps or slows down on denormals. Mirror lanes' unused draws too.
        // (Their surfaces are real ones already.)
        const int first = std::countr_zero(in_lanes);
        for (int l = 0; l < K; ++l) {
            if ((mirror >> l) & 1u) u1[l] = u2[l] = 0.0f;
            if ((in_lanes >> l) & 1u) continue;
            for (int a = 0; a < 3; ++a) {
                albedo[a][l] = albedo[a][first];
                beta[a][l] = beta[a][first];
            }
            total[l] = total[first];
            wd[l] = wd[first];
            mirror_weight[l] = mirror_weight[first];
            roulette[l] = roulette[first];
            u1[l] = u1[first];
            u2[l] = u2[first];
        }
        const auto load3 = [](const float (&v)[3][K]) {
            return Vec3<F>{F::load_aligned(v[0]), F::load_aligned(v[1]), F::load_aligned(v[2])};
        };
        const auto store3 = [](float (&v)[3][K], const Vec3<F>& x) {
            x.x.store_aligned(v[0]);
            x.y.store_aligned(v[1]);
            x.z.store_aligned(v[2]);
        };
        // The surface seen from the ray's side (bounce(): its wo = -view, and
        // dot(wo, g) > 0 is dot(view, g) < 0 bit for bit).
        const Vec3<F>& d = surf.direction;
        const Vec3<F> view = d / vsqrt(dot(d, d));
        Vec3<F> ng, ns;
        face_viewer(view, surf.geometric_normal, surf.shading_normal, ng, ns);
        const Vec3<F> above = offset_lanes(offset_, surf.point, ng);
        alignas(64) float above_l[3][K];
        store3(above_l, above);

        // Next-event estimation's light per lane (direct_light()): its
        // kind, and the point to aim at or the direction toward it.
        enum : int { kNone, kPoint, kDistant, kArea };
        alignas(64) float target[3][K], light_n[3][K], color[3][K], pdf_area[K];
        int kind[K];
        const std::size_t n_point = scene_.lights.size(), n_distant = scene_.distant_lights.size();
        const std::size_t n_lights = n_point + n_distant + scene_.area_lights.size();
        const float choose = float(n_lights);
        for (int l = 0; l < K; ++l) {
            kind[l] = kNone;
            for (int a = 0; a < 3; ++a) target[a][l] = light_n[a][l] = color[a][l] = 0.0f;
            pdf_area[l] = 1.0f;
            if (!((diffuse >> l) & 1u) || n_lights == 0) continue;
            const std::size_t i = paths[std::size_t(l)];
            const Sample2 u = drawn(s, i, 1);
            const std::size_t pick = std::min(n_lights - 1, std::size_t(u.x * choose));
            Vec3f t, c;
            if (pick < n_point) {
                kind[l] = kPoint;
                t = scene_.lights[pick].position;
                c = scene_.lights[pick].color;
            } else if (pick < n_point + n_distant) {
                kind[l] = kDistant;
                t = -scene_.distant_lights[pick - n_point].direction;  // the direction toward it
                c = scene_.distant_lights[pick - n_point].color;
            } else {
                kind[l] = kArea;
                const std::size_t index = pick - n_point - n_distant;
                const AreaLight& light = scene_.area_lights[index];
                const Sample2 v = drawn(s, i, 2);
                LightSample ls;
                if (light.shape == AreaLightShape::Parallelogram) {
                    // sample_area_light's point, with its normal and density computed once.
                    ls = parallelograms_[index];
                    ls.point = light.corner + light.edge1 * v.x + light.edge2 * v.y;
                } else {
                    ls = sample_area_light(light, {above_l[0][l], above_l[1][l], above_l[2][l]}, v);
                }
                t = ls.point;
                c = light.color;
                pdf_area[l] = ls.pdf_area;
                for (int a = 0; a < 3; ++a) light_n[a][l] = ls.normal[a];
            }
            for (int a = 0; a < 3; ++a) {
                target[a][l] = t[a];
                color[a][l] = c[a];
            }
        }
        alignas(64) float kind_f[K];
        for (int l = 0; l < K; ++l) kind_f[l] = float(kind[l]);
        const F kinds = F::load_aligned(kind_f);
        const auto is_distant = kinds == F(float(kDistant)), is_area = kinds == F(float(kArea));
        const auto is_point = kinds == F(float(kPoint));
        // direct_light(): toward a point (a point light or a point on an area
        // light), or along a distant light's direction.
        const Vec3<F> tg = load3(target);
        const Vec3<F> to = tg - above;
        const F dist2 = dot(to, to);
        const Vec3<F> toward = to / vsqrt(dist2);
        const Vec3<F> wi{select(is_distant, tg.x, toward.x), select(is_distant, tg.y, toward.y),
                         select(is_distant, tg.z, toward.z)};
        const F cos_s = dot(ns, wi);
        const F cos_l = -dot(load3(light_n), wi);
        auto lit = (is_point | is_distant | is_area) & !(cos_s <= F(0.0f)) & !(dot(ng, wi) <= F(0.0f));
        const auto no_distance = !(dist2 > F(0.0f));
        lit = lit & !(is_area & (no_distance | (cos_l <= F(0.0f))));
        const F pdf = F::load_aligned(pdf_area), n_choose(choose);
        const F pdf_light = pdf * dist2 / cos_l / n_choose;
        const F bsdf_pdf = cos_s * F(kInvPi);
        const F mis = pdf_light * pdf_light / (pdf_light * pdf_light + bsdf_pdf * bsdf_pdf);
        const F scale = select(is_distant, cos_s * n_choose,
                               select(is_area, cos_s * cos_l / (dist2 * pdf) * n_choose * mis, cos_s / dist2 * n_choose));
        const F share = F::load_aligned(total) / F::load_aligned(wd);
        const Vec3<F> alb = load3(albedo), b = load3(beta);
        const Vec3<F> f{alb.x * F(kInvPi), alb.y * F(kInvPi), alb.z * F(kInvPi)};
        const Vec3<F> nee_beta{b.x * share, b.y * share, b.z * share};
        const Vec3<F> c = load3(color);
        const Vec3<F> contribution{nee_beta.x * f.x * c.x * scale, nee_beta.y * f.y * c.y * scale,
                                   nee_beta.z * f.z * c.z * scale};
        alignas(64) float contribution_l[3][K], shadow_dir[3][K];
        store3(contribution_l, contribution);
        store3(shadow_dir, Vec3<F>{select(is_distant, tg.x, to.x), select(is_distant, tg.y, to.y),
                                   select(is_distant, tg.z, to.z)});
        const std::uint32_t lit_bits = mask_bits(lit);

        // The next rays (none where no ray could carry light back).
        alignas(64) float out_dir_l[3][K], next_beta_l[3][K], bounce_pdf_l[K];
        std::uint32_t alive = 0;
        if (spawn) {
            // The cosine-weighted bounce, as bounce()'s cosine_hemisphere.
            const F r = vsqrt(F::load_aligned(u1));
            F sin_phi, cos_phi;
            sin_cos_turns(F::load_aligned(u2), sin_phi, cos_phi);
            const F lx = r * cos_phi, ly = r * sin_phi;
            const F lz = vsqrt(std_max(F(0.0f), F(1.0f) - lx * lx - ly * ly));
            const Vec3<F> diffuse_dir = to_world_lanes(ns, lx, ly, lz);
            // The mirror direction of wo = -view about ns, and the mirror's weight.
            const Vec3<F> wo = -view;
            const Vec3<F> mirror_dir = ns * (F(2.0f) * dot(wo, ns)) - wo;
            alignas(64) float mirror_lane[K];
            for (int l = 0; l < K; ++l) mirror_lane[l] = (mirror >> l) & 1u ? 1.0f : 0.0f;
            const auto mirrored = F::load_aligned(mirror_lane) > F(0.0f);
            const Vec3<F> out_dir{select(mirrored, mirror_dir.x, diffuse_dir.x),
                                  select(mirrored, mirror_dir.y, diffuse_dir.y),
                                  select(mirrored, mirror_dir.z, diffuse_dir.z)};
            const F bounce_pdf = select(mirrored, F(0.0f), lz * F(kInvPi));
            const F w = F::load_aligned(mirror_weight);
            Vec3<F> next_beta{select(mirrored, b.x * w, b.x * (alb.x * share)),
                              select(mirrored, b.y * w, b.y * (alb.y * share)),
                              select(mirrored, b.z * w, b.z * (alb.z * share))};
            alive = in_lanes;
            if (depth > path_.rr_depth) {
                const F q = std_min(F(1.0f), max_component_lanes(next_beta));
                alive &= mask_bits(F::load_aligned(roulette) < q);
                next_beta = next_beta / q;
            }
            alive &= mask_bits(max_component_lanes(next_beta) > F(0.0f));
            store3(out_dir_l, out_dir);
            store3(next_beta_l, next_beta);
            bounce_pdf.store_aligned(bounce_pdf_l);
        }

        // Append in path order, as bounce() would have. Written component
        // by component from the lane arrays: a Vec3f assembled on the stack
        // and copied in 8-byte pieces stalls on store forwarding (a tenth of
        // this function).
        const auto set = [](Vec3f& v, const float (&lanes)[3][K], int l) {
            v.x = lanes[0][l];
            v.y = lanes[1][l];
            v.z = lanes[2][l];
        };
        for (int l = 0; l < n; ++l) {
            const std::size_t i = paths[std::size_t(l)];
            if (!((in_lanes >> l) & 1u)) {
                if (!((nothing_to_do >> l) & 1u)) one_by_one(i);
                continue;
            }
            const bool specular = (mirror >> l) & 1u;
            const std::uint32_t si = p.sample[i];
            if ((lit_bits >> l) & 1u) {
                ++s.stats.shadow_rays;
                s.shadows.reserve_more(1);  // one_by_one's shadow rays take room too
                const std::size_t k = s.shadows.append_reserved();
                Rayf& ray = s.shadows.rays[k];  // spawn_ray / spawn_ray_to
                set(ray.org, above_l, l);
                set(ray.dir, shadow_dir, l);
                ray.tnear = offset_.tnear();
                ray.tfar = kind[l] == kDistant ? std::numeric_limits<float>::infinity() : kShadowRayEnd;
                s.shadows.sample[k] = si;
                set(s.shadows.contribution[k], contribution_l, l);
            }
            if (!((alive >> l) & 1u)) continue;
            if (specular) ++s.stats.reflect_rays;
            else ++s.stats.diffuse_rays;
            // Paths::add(next beta, si, specular, bounce pdf, origin) and spawn_ray.
            Paths& next = s.next;
            next.reserve_more(1);
            const std::size_t k = next.append_reserved();
            next.bounce_pdf[k] = bounce_pdf_l[l];
            set(next.bounce_origin[k], above_l, l);
            set(next.throughput[k], next_beta_l, l);
            next.sample[k] = si;
            next.count_emission[k] = specular;
            Rayf& ray = next.rays[k];
            set(ray.org, above_l, l);
            set(ray.dir, out_dir_l, l);
            ray.tnear = offset_.tnear();
            ray.tfar = std::numeric_limits<float>::infinity();
        }
    }

    /// Radiance an area light's surface emits toward `wo`: its colour on
    /// the emitting side of a parallelogram, everywhere on a sphere's
    /// outside.
    Vec3f emitted(std::int32_t light, const Vec3f& geometric_normal, const Vec3f& wo) const {
        const AreaLight& l = scene_.area_lights[std::size_t(light)];
        if (l.shape == AreaLightShape::Parallelogram && dot(cross(l.edge1, l.edge2), wo) <= 0) return {};
        if (l.shape == AreaLightShape::Sphere && dot(geometric_normal, wo) <= 0) return {};
        return l.color;
    }

    /// Probability of choosing a given light in direct_light.
    float light_choice_pdf() const {
        return 1.0f / float(scene_.lights.size() + scene_.distant_lights.size() + scene_.area_lights.size());
    }

    static float power_heuristic(float f, float g) { return f * f / (f * f + g * g); }

    /// One shadow ray to one light chosen uniformly among all of them
    /// (point, distant, area), weighted by their number.
    void direct_light(std::size_t path, std::uint32_t si, const Vec3f& above, const Vec3f& ns, const Vec3f& ng,
                      const Vec3f& beta, const Vec3f& f, Scratch& s) const {
        const std::size_t n_point = scene_.lights.size(), n_distant = scene_.distant_lights.size();
        const std::size_t n = n_point + n_distant + scene_.area_lights.size();
        if (n == 0) return;
        const Sample2 u = drawn(s, path, 1);
        const std::size_t pick = std::min(n - 1, std::size_t(u.x * float(n)));
        const float choose = float(n);
        Vec3f contribution, target, wi_distant;
        bool distant = false;
        if (pick < n_point) {
            const PointLight& l = scene_.lights[pick];
            const Vec3f d = l.position - above;
            const float dist2 = dot(d, d);
            const Vec3f wi = d / std::sqrt(dist2);
            const float cos_s = dot(ns, wi);
            if (cos_s <= 0 || dot(ng, wi) <= 0) return;
            contribution = beta * f * l.color * (cos_s / dist2 * choose);
            target = l.position;
        } else if (pick < n_point + n_distant) {
            const DistantLight& l = scene_.distant_lights[pick - n_point];
            const Vec3f wi = -l.direction;
            const float cos_s = dot(ns, wi);
            if (cos_s <= 0 || dot(ng, wi) <= 0) return;
            contribution = beta * f * l.color * (cos_s * choose);
            wi_distant = wi;
            distant = true;
        } else {
            const AreaLight& l = scene_.area_lights[pick - n_point - n_distant];
            const Sample2 v = drawn(s, path, 2);
            const LightSample ls = sample_area_light(l, above, v);
            const Vec3f d = ls.point - above;
            const float dist2 = dot(d, d);
            if (!(dist2 > 0)) return;
            const Vec3f wi = d / std::sqrt(dist2);
            const float cos_s = dot(ns, wi), cos_l = -dot(ls.normal, wi);
            if (cos_s <= 0 || dot(ng, wi) <= 0 || cos_l <= 0) return;
            // Multiple importance sampling with the diffuse bounce (cos / pi).
            const float pdf_light = ls.pdf_area * dist2 / cos_l / choose;
            const float w = power_heuristic(pdf_light, cos_s * kInvPi);
            contribution = beta * f * l.color * (cos_s * cos_l / (dist2 * ls.pdf_area) * choose * w);
            target = ls.point;
        }
        ++s.stats.shadow_rays;
        s.shadows.reserve_more(1);
        const std::size_t k = s.shadows.append_reserved();
        Rayf& r = s.shadows.rays[k];  // written in place, as Paths::add's rays
        if (distant) spawn_ray(above, wi_distant, offset_, r);
        else spawn_ray_to(above, target, offset_, r);
        s.shadows.sample[k] = si;
        s.shadows.contribution[k] = contribution;
    }

    void trace_shadows(Scratch& s) const {
        Shadows& b = s.shadows;
        if (b.rays.empty()) return;
        b.occluded.resize_for_overwrite(b.rays.size());
        const auto times = timed_ ? times_of(b.sample, s) : std::span<const float>{};
        if (options_.ray_log) options_.ray_log->add(RayLog::Shadow, b.rays, times);
        if (timed_) accel_.occluded_at(options_.secondary_packet, b.rays, times, b.occluded);
        else accel_.occluded_packets(options_.secondary_packet, b.rays, b.occluded);
        for (std::size_t k = 0; k < b.rays.size(); ++k)
            if (!b.occluded[k]) s.radiance[b.sample[k]] += b.contribution[k];
    }
};

}  // namespace

RenderStats render_path(const Scene& scene, const Accel& accel, const WhittedOptions& options,
                        const PathOptions& path, Image& image) {
    const auto start = std::chrono::steady_clock::now();
    const CameraFrame frame = make_camera_frame(scene.camera, options.width, options.height);
    const PathTracer tracer(scene, accel, options, path);
    const int spp = options.spp;
    const TileGrid grid = render_tiles(scene, options, accel, false);
    PerWorker<Scratch> scratch;
    TileProgress progress(std::uint64_t(options.width) * std::uint64_t(options.height), options.progress,
                          options.progress_context);
    std::optional<Film> own_film;
    Film& film = options.film && options.film->has_size(options.width, options.height)
                     ? *options.film
                     : own_film.emplace(options.width, options.height);
    if (image.width != options.width || image.height != options.height) image = Image(options.width, options.height);
    std::vector<FilmNoise> tile_noise(std::size_t(grid.count()));  // summed in tile order
    for_each_tile(grid, [&](int tile, int slot) {
        Scratch& s = scratch.at(slot);
        grid.pixels(tile, s.pixels);
        // Samples in chunks of about kMaxBatch paths, whatever --spp is.
        const int chunk = std::max(1, int(kMaxBatch / s.pixels.size()));
        for (int k0 = 0; k0 < spp; k0 += chunk) {
            const int k1 = std::min(spp, k0 + chunk);
            const std::size_t n = s.pixels.size() * std::size_t(k1 - k0);
            s.paths.start_camera_paths(n);
            s.radiance.assign(n, Vec3f{});
            s.camera.draw(frame, scene.camera, tracer.samples(), options.filter, s.pixels, options.width, k0, k1,
                          s.paths.rays.data(), &scene);
            tracer.trace(s);
            std::size_t i = 0;
            for (const PixelXY& px : s.pixels) {
                film.add(px.x, px.y, std::span(s.radiance).subspan(i, std::size_t(k1 - k0)));
                i += std::size_t(k1 - k0);
            }
        }
        // The tile's pixels are final: resolved on the tile's thread.
        const auto [x0, y0, x1, y1] = grid.rect(tile);
        tile_noise[std::size_t(tile)] = film.resolve(x0, y0, x1, y1, image);
        progress.add(s.pixels.size());
    });
    RenderStats stats;
    FilmNoise noise;
    for (const FilmNoise& n : tile_noise) noise += n;
    stats.noise_rms = noise.rms();
    scratch.for_each([&](const Scratch& s) { stats += s.stats; });
    stats.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

}  // namespace raypack
