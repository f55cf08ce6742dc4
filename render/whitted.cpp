#include "render/whitted.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "render/camera_rays.h"
#include "render/camera_samples.h"
#include "render/light_sampling.h"
#include "render/phong_power.h"
#include "render/ray_coherence.h"
#include "render/sampling.h"
#include "render/shade_lanes.h"
#include "render/shading_points.h"
#include "render/surface.h"
#include "render/surface_lanes.h"
#include "render/thin_lens.h"
#include "render/tiles.h"

namespace raypack {

RenderStats& RenderStats::operator+=(const RenderStats& o) {
    eye_rays += o.eye_rays;
    eye_hits += o.eye_hits;
    reflect_rays += o.reflect_rays;
    refract_rays += o.refract_rays;
    shadow_rays += o.shadow_rays;
    diffuse_rays += o.diffuse_rays;
    return *this;
}

namespace {

/// Eye rays (camera samples) per batch of a tile, at most (and at least one
/// sample per pixel).
constexpr std::size_t kMaxBatch = 16384;

/// The ray tree of one batch of eye rays, stored level by level: the rays of
/// depth d occupy [level_begin, level_end) and their children are appended
/// after them. Each ray keeps its local colour (ambient and direct light);
/// each ray with children has a link to them. Once the deepest level is
/// shaded, colours are summed bottom-up in the order the recursive tracer
/// added them, so the result is the recursion's bit for bit.
struct RayTree {
    /// A ray's children and their weights.
    struct Link {
        std::int32_t parent;
        std::int32_t reflect = -1, refract = -1;  ///< -1 if none
        float ks = 0, kt = 0;                     ///< kt: 0 if not transmitting
    };
    std::vector<Rayf> rays;
    std::vector<Hitf> hits;
    std::vector<Vec3f> color;
    std::vector<std::uint64_t> sample;  ///< pixel * spp + sample index of the camera sample
    /// Scene time of each ray (its camera sample's), when the scene moves
    /// and the render samples time; otherwise unused.
    std::vector<float> time;
    std::vector<Link> links;            ///< in the order of their parents
    std::size_t count = 0;              ///< rays in use; the arrays only grow

    /// Starts a tree of `eye` rays (to be written to rays[0 .. eye)).
    void reset(std::size_t eye) {
        reserve(eye);
        count = eye;
        links.clear();
    }
    /// A new ray (set by the caller through the returned index).
    std::int32_t add() {
        if (count == rays.size()) reserve(count + 1);  // the call only when full (it was not inlined)
        return std::int32_t(count++);
    }

private:
    void reserve(std::size_t n) {
        if (n <= rays.size()) return;
        const std::size_t size = std::max(n, 2 * rays.size());
        rays.resize(size);
        hits.resize(size);
        color.resize(size);
        sample.resize(size);
        time.resize(size);
    }
};

/// Shadow rays of one level, grouped by light (rays toward one light
/// converge on it, so a packet of them is coherent).
struct ShadowBatch {
    std::vector<ShadowQueue> per_light;
    std::vector<Rayf> all;
    std::vector<float> times;  ///< moving scenes: each ray's, its owner's
    std::vector<std::uint8_t> occluded;

    void reset(std::size_t lights) {
        if (per_light.size() < lights) per_light.resize(lights);
        for (ShadowQueue& q : per_light) q.clear();
    }
};

/// What a shaded point's reflection and refraction rays need beyond its
/// entry in ShadingPoints.
struct SpawnPoint {
    Vec3f p;  ///< the hit point before the offset
    std::uint32_t material;
    bool front;  ///< the ray met the outward side
};

struct Scratch {
    RayTree tree;
    ShadowBatch shadows;
    ShadingPoints points;
    std::vector<SpawnPoint> spawn;
    /// Transmitting points of the level (shading point, link) whose
    /// refraction rays follow all the level's reflection rays.
    std::vector<std::pair<std::size_t, std::size_t>> refracting;
    std::vector<PixelXY> pixels;
    CameraSampleBatch camera;           ///< distribution: the batch's camera samples
    std::vector<Sampler::Draw> draws;   ///< points on area lights: the level's draws (Sampler::get_many)
    /// Points on area lights for one level: light a, point j, sample k at
    /// (a * points + j) * light samples + k.
    std::vector<Sample2> light_drawn;
    RenderStats stats;
};

class WhittedWavefront {
public:
    WhittedWavefront(const Scene& scene, const Accel& accel, const WhittedOptions& options)
        : scene_(scene),
          accel_(accel),
          options_(options),
          offset_(options.offset, scene),
          surfaces_(scene),
          // SPD Readme: each light and the ambient term get sqrt(L) / (2 L),
          // L counting lights of every kind.
          intensity_(scene.spd_light_intensity()),
          samples_(options.distribution ? options.sampler : SamplerKind::Regular,
                   options.distribution ? options.spp : 1, options.seed),
          light_samples_(options.distribution ? options.sampler : SamplerKind::Regular,
                         options.distribution ? options.light_samples : 1, options.seed ^ 0x5bd1e995ull),
          // Whitted traces every ray at the shutter's opening (one sample,
          // no time); distribution ray tracing samples time per camera sample.
          timed_(options.distribution && !scene.moving_instances.empty()),
          // Surfaces in SIMD lanes need the Epsilon or Scaled offset (the
          // robust one reads the primitive) and a static scene.
          lanes_(options.surface_lanes && !timed_ && options.offset != OffsetPolicy::Robust && kShadeLanes > 1) {
        specular_cutoff_.reserve(scene.materials.size());
        for (const Material& m : scene.materials) {
            specular_cutoff_.push_back(specular_cutoff(m.shine));
            ambient_.push_back(m.color * (intensity_ * m.kd));  // add_point's ambient term
            spawns_ = spawns_ || m.ks > 0 || m.transmittance > 0;
            material_light_.push_back(m.area_light);
            const float terms[7] = {m.color.x, m.color.y, m.color.z, m.kd, m.ks, m.shine, specular_cutoff_.back()};
            for (int k = 0; k < 7; ++k) material_terms_[k].push_back(terms[k]);
        }
    }

    /// Light buckets: point lights, then distant lights, then area lights.
    std::size_t light_buckets() const {
        return scene_.lights.size() + scene_.distant_lights.size() + scene_.area_lights.size();
    }

    /// Camera samples k0 .. k1 of every pixel of `pixels`, pixel by pixel, for
    /// distribution ray tracing: positions drawn from the pixel filter
    /// (sampler dimension 0) and lens points (dimension 1), all at once.
    void camera_samples(std::span<const PixelXY> pixels, int k0, int k1, const CameraFrame& frame, Scratch& s) const {
        s.camera.draw(frame, scene_.camera, samples_, options_.filter, pixels, options_.width, k0, k1, s.tree.rays.data(),
                      &scene_);
        if (timed_) std::copy(s.camera.time.begin(), s.camera.time.end(), s.tree.time.begin());
        const auto spp = std::uint64_t(samples_.spp());
        std::size_t i = 0;
        for (const PixelXY& px : pixels) {
            const std::uint64_t pixel = std::uint64_t(px.y) * std::uint64_t(options_.width) + std::uint64_t(px.x);
            for (int k = k0; k < k1; ++k, ++i) s.tree.sample[i] = pixel * spp + std::uint64_t(k);
        }
    }

    /// The lens point of the sample with key `key` (sampler dimension 1).
    Sample2 lens_sample(std::uint64_t key) const {
        const auto spp = std::uint64_t(samples_.spp());
        return samples_.get(key / spp, int(key % spp), 1);
    }

    /// Whether rays carry times (RayTree::time).
    bool timed() const { return timed_; }
    /// The scene time of the sample with key `key` (dimension kTimeDimension).
    float time_sample(std::uint64_t key) const {
        const auto spp = std::uint64_t(samples_.spp());
        const float u = samples_.line(samples_.get(key / spp, int(key % spp), kTimeDimension));
        return (1.0f - u) * scene_.shutter_open + u * scene_.shutter_close;
    }

    /// Traces the whole ray tree of the eye rays s.tree.rays[0 .. eye) (set
    /// after s.tree.reset(eye)); their colours end in s.tree.color[0 .. eye).
    void trace(std::size_t eye, Scratch& s) const {
        RayTree& tree = s.tree;
        intersect(RayLog::Eye, 0, eye, tree);
        std::size_t begin = 0, end = eye;
        for (int depth = 1; begin < end; ++depth) {
            const bool streamed = depth > 1 && intersect(RayLog::Bounce, begin, end, tree);
            shade_level(begin, end, depth, streamed, s);
            begin = end;
            end = tree.count;
        }
        // Children come after their parents: one backward pass sums the tree.
        for (std::size_t k = tree.links.size(); k-- > 0;) {
            const RayTree::Link& link = tree.links[k];
            Vec3f c = tree.color[std::size_t(link.parent)];
            if (link.reflect >= 0) c += tree.color[std::size_t(link.reflect)] * link.ks;
            if (link.kt > 0) {
                // Total internal reflection sends the transmitted share along the reflection ray.
                const std::int32_t t = link.refract >= 0 ? link.refract : link.reflect;
                c += tree.color[std::size_t(t)] * link.kt;
            }
            tree.color[std::size_t(link.parent)] = c;
        }
    }

private:
    const Scene& scene_;
    const Accel& accel_;
    const WhittedOptions& options_;
    RayOffset offset_;
    SurfaceTable surfaces_;
    float intensity_ = 1;
    std::vector<float> specular_cutoff_;  ///< per material, see specular_cutoff
    std::vector<Vec3f> ambient_;          ///< per material, the ambient term
    /// Per material, for the surface loop's gathers: its area light (or -1),
    /// and its colour, kd, ks, shine and specular cut-off as ShadingPoints
    /// stores them.
    std::vector<std::int32_t> material_light_;
    std::vector<float> material_terms_[7];
    Sampler samples_;        ///< camera samples: pixel position, lens, glossy lobes
    Sampler light_samples_;  ///< points on area lights
    bool timed_;             ///< rays carry times (RayTree::time)
    bool lanes_;             ///< hits become shading points in SIMD lanes (add_points_in_lanes)
    bool spawns_ = false;    ///< some material reflects or transmits (spawn_reflection)

    /// Closest hits of the tree's rays [begin, end) (eye rays or bounces),
    /// at their times if timed. Bounces that go every which way (off curved
    /// mirrors) walk the structure as one stream; true if they did.
    bool intersect(RayLog::Kind kind, std::size_t begin, std::size_t end, RayTree& tree) const {
        const int width = kind == RayLog::Eye ? options_.packet : options_.secondary_packet;
        const auto rays = std::span(tree.rays).subspan(begin, end - begin);
        const auto hits = std::span(tree.hits).subspan(begin, end - begin);
        const auto times = std::span(tree.time).subspan(begin, timed_ ? end - begin : 0);
        if (options_.ray_log) options_.ray_log->add(kind, rays, times);
        if (timed_) {
            accel_.intersect_at(width, rays, times, hits);
            return false;
        }
        if (kind == RayLog::Bounce && accel_.supports_stream() && incoherent(rays)) {
            accel_.intersect_stream(width, rays, hits);
            return true;
        }
        accel_.intersect_packets(width, rays, hits);
        return false;
    }

    /// Shades the rays [begin, end) of the tree, which are of depth `depth`:
    /// first each hit's surface (in ray order), then each point light for
    /// all points at once, then the other lights and the children. The
    /// shadow rays from the hits of `streamed` rays go as a stream too.
    void shade_level(std::size_t begin, std::size_t end, int depth, bool streamed, Scratch& s) const {
        RayTree& tree = s.tree;
        s.shadows.reset(light_buckets());
        s.points.clear();
        s.spawn.clear();
        RenderStats& stats = s.stats;
        if (depth == 1) {
            stats.eye_rays += end - begin;
            for (std::size_t i = begin; i < end; ++i) stats.eye_hits += tree.hits[i].found();
        }
        if (lanes_) {
            add_points_in_lanes(begin, end, s);
        } else {
            for (std::size_t i = begin; i < end; ++i) {
                const Hitf& hit = tree.hits[i];
                if (!hit.found()) {
                    tree.color[i] = scene_.background;
                    continue;
                }
                add_point(std::int32_t(i), tree.rays[i], hit, s);
            }
        }
        const Attenuation attenuation{options_.atten_c0, options_.atten_c1, options_.atten_c2};
        for (std::size_t li = 0; li < scene_.lights.size(); ++li)
            stats.shadow_rays +=
                shade_point_light(s.points, scene_.lights[li], intensity_, attenuation, offset_, s.shadows.per_light[li]);
        if (!scene_.distant_lights.empty())
            for (std::size_t j = 0; j < s.points.size(); ++j) shade_distant_lights(j, s);
        if (!scene_.area_lights.empty()) {
            // The SPD intensity spread evenly over each light's area: the
            // mean of point lights at stratified points of it, each shining
            // from the emitting side only.
            draw_area_light_samples(depth, s);
            const int n_light = light_samples_.spp();
            const std::size_t per_light = s.points.size() * std::size_t(n_light);
            std::size_t bucket = scene_.lights.size() + scene_.distant_lights.size();
            for (std::size_t a = 0; a < scene_.area_lights.size(); ++a, ++bucket) {
                const AreaLight& light = scene_.area_lights[a];
                // Whitted lights a sphere from the point facing the shaded point.
                const bool facing_point = !options_.distribution && light.shape == AreaLightShape::Sphere;
                stats.shadow_rays +=
                    shade_area_light(s.points, light, std::span(s.light_drawn).subspan(a * per_light, per_light),
                                     n_light, intensity_, facing_point, offset_, s.shadows.per_light[bucket]);
            }
        }
        if (depth < options_.max_depth && spawns_) {
            // All reflection rays of the level, then all refraction rays: a
            // point's two children go opposite ways, so interleaved they
            // would make every packet of the next level incoherent.
            s.refracting.clear();
            for (std::size_t j = 0; j < s.points.size(); ++j) spawn_reflection(j, depth, s);
            for (const auto& [j, link] : s.refracting) spawn_refraction(j, link, s);
        }
        trace_shadows(s, streamed);
    }

    /// n, or -n unless `keep`, component by component: a whole-vector
    /// select copied the Surface through the stack in 8-byte pieces that
    /// stalled on the 4-byte stores that wrote it (store forwarding).
    static Vec3f toward(const Vec3f& n, bool keep) {
        return {keep ? n.x : -n.x, keep ? n.y : -n.y, keep ? n.z : -n.z};
    }

    /// The hit's surface as a shading point, its ambient term as the colour
    /// (or the colour of the area light it lies on).
    void add_point(std::int32_t i, const Rayf& ray, const Hitf& hit, Scratch& s) const {
        RayTree& tree = s.tree;
        const float time = timed_ ? tree.time[std::size_t(i)] : -std::numeric_limits<float>::infinity();
        const Surface surf = surfaces_.at(ray, hit, time);
        const Material& m = scene_.materials[surf.material];
        if (m.area_light >= 0) {
            // A light's own surface shows the light's colour.
            tree.color[std::size_t(i)] = scene_.area_lights[std::size_t(m.area_light)].color;
            return;
        }
        const Vec3f view = normalize(ray.dir);
        // Shade the side the ray arrives on: both normals face the viewer.
        const bool front = dot(view, surf.geometric_normal) < 0;
        const Vec3f ng = toward(surf.geometric_normal, front);
        Vec3f ns = toward(surf.shading_normal, front);
        if (dot(ns, ng) < 0) ns = ng;  // interpolated normal bent past the surface
        const Vec3f p = offset_.hit_point(scene_, ray, hit, surf.point, time);
        tree.color[std::size_t(i)] = m.color * (intensity_ * m.kd);  // ambient
        s.points.add(i, view, ns, ng, offset_.offset(p, ng), m, specular_cutoff_[surf.material]);
        s.spawn.push_back({p, surf.material, front});
    }

    /// add_point for the rays [begin, end), bit for bit, K rays at a time
    /// in SIMD lanes: their surfaces gathered (SurfaceLanes), view
    /// directions, normals and offset points computed in the lanes, and the
    /// lanes that are shaded packed into s.points in ray order (the order
    /// add_point gives); misses and lights' surfaces coloured on the way.
    void add_points_in_lanes(std::size_t begin, std::size_t end, Scratch& s) const {
        constexpr int K = kShadeLanes;
        static_assert(K <= int(ShadingPoints::kSpare));
        using F = vfloat<K>;
        using I = vint<K>;
        RayTree& tree = s.tree;
        // Where a point's reflection and refraction rays start, and its
        // material for the distant lights.
        const bool spawn = spawns_ || !scene_.distant_lights.empty();
        alignas(64) std::int32_t iota[K];
        for (int l = 0; l < K; ++l) iota[l] = l;
        const I lanes = I::load_aligned(iota);
        SurfaceLanes<K> surf;
        alignas(64) std::int32_t material[K];
        alignas(64) float point[3][K];
        for (std::size_t i0 = begin; i0 < end; i0 += K) {
            const int count = int(std::min<std::size_t>(K, end - i0));
            std::uint32_t found = 0;
            for (int l = 0; l < count; ++l) found |= std::uint32_t(tree.hits[i0 + std::size_t(l)].found()) << l;
            for (std::uint32_t bits = ~found & ((2u << (count - 1)) - 1); bits != 0; bits &= bits - 1)
                tree.color[i0 + std::size_t(std::countr_zero(bits))] = scene_.background;
            if (found == 0) continue;
            // Lanes past the last ray read the last one (masked off).
            const I last(std::int32_t(i0) + count - 1), index = I(std::int32_t(i0)) + lanes;
            const I clamped = xsimd::select(index > last, last, index);
            if (count == K) surf.load(surfaces_, tree.rays.data(), tree.hits.data(), i0, clamped, found);
            else surf.gather(surfaces_, tree.rays.data(), tree.hits.data(), clamped, found);
            surf.material.store_aligned(material);
            // Most blocks lie on one material: its terms once.
            const std::int32_t first = first_lane<K>(surf.material, found);
            const bool one_material = (int_mask_bits<K>(surf.material == I(first)) & found) == found;
            const auto terms = [&](int k) {
                return one_material ? F(material_terms_[k][std::size_t(first)])
                                    : gather_floats<K>(material_terms_[k].data(), surf.material);
            };
            // A light's own surface shows the light's colour.
            const std::uint32_t lit =
                found & (one_material ? (material_light_[std::size_t(first)] >= 0 ? ~0u : 0u)
                                      : int_mask_bits<K>(gather_ints<K>(material_light_.data(), surf.material) >= I(0)));
            const std::uint32_t shaded = found & ~lit;
            for (std::uint32_t bits = found; bits != 0; bits &= bits - 1) {
                const int l = std::countr_zero(bits);
                const Material& m = scene_.materials[std::size_t(material[l])];
                tree.color[i0 + std::size_t(l)] = (lit >> l) & 1u ? scene_.area_lights[std::size_t(m.area_light)].color
                                                                  : ambient_[std::size_t(material[l])];
            }
            if (shaded == 0) continue;
            const Vec3<F>& d = surf.direction;
            const Vec3<F> v = d / vsqrt(dot(d, d));
            Vec3<F> ng, ns;
            const auto front = face_viewer(v, surf.geometric_normal, surf.shading_normal, ng, ns);
            const Vec3<F> up = offset_lanes(offset_, surf.point, ng);
            const ShadingPoints::Block out = s.points.next_block();
            store_packed<K>(out.ray, I(std::int32_t(i0)) + lanes, shaded);
            for (int a = 0; a < 3; ++a) {
                store_packed<K>(out.view[a], v[a], shaded);
                store_packed<K>(out.ns[a], ns[a], shaded);
                store_packed<K>(out.ng[a], ng[a], shaded);
                store_packed<K>(out.above[a], up[a], shaded);
                store_packed<K>(out.color[a], terms(a), shaded);
            }
            store_packed<K>(out.kd, terms(3), shaded);
            store_packed<K>(out.ks, terms(4), shaded);
            store_packed<K>(out.shine, terms(5), shaded);
            store_packed<K>(out.cutoff, terms(6), shaded);
            s.points.commit(std::size_t(std::popcount(shaded)));
            if (!spawn) continue;
            for (int a = 0; a < 3; ++a) surf.point[a].store_aligned(point[a]);
            const std::uint32_t front_bits = mask_bits(front);
            for (std::uint32_t bits = shaded; bits != 0; bits &= bits - 1) {
                const int l = std::countr_zero(bits);
                SpawnPoint& sp = s.spawn.emplace_back();
                sp.p.x = point[0][l];
                sp.p.y = point[1][l];
                sp.p.z = point[2][l];
                sp.material = std::uint32_t(material[l]);
                sp.front = (front_bits >> l) & 1u;
            }
        }
    }

    /// The unit-square points of every area light's samples at every
    /// shading point of the level, all at once (Sampler::get_many).
    void draw_area_light_samples(int depth, Scratch& s) const {
        const int n_light = light_samples_.spp();
        s.draws.resize(s.points.size() * std::size_t(n_light));
        Sampler::Draw* draw = s.draws.data();
        for (std::size_t j = 0; j < s.points.size(); ++j) {
            const Sampler::Pixel key = light_samples_.pixel(s.tree.sample[std::size_t(s.points.ray(j))]);
            for (int k = 0; k < n_light; ++k) *draw++ = {key, k};
        }
        s.light_drawn.resize(scene_.area_lights.size() * s.draws.size());
        for (std::size_t a = 0; a < scene_.area_lights.size(); ++a)
            light_samples_.get_many(s.draws, depth * 64 + int(a % 64), s.light_drawn.data() + a * s.draws.size());
    }

    /// Distant lights at shading point j (point and area lights are done
    /// for all points at once by shade_point_light and shade_area_light).
    void shade_distant_lights(std::size_t j, Scratch& s) const {
        const ShadingPoints& pts = s.points;
        const std::int32_t i = pts.ray(j);
        const Material& m = scene_.materials[s.spawn[j].material];
        const float cutoff = specular_cutoff_[s.spawn[j].material];
        const Vec3f view = pts.view(j), ns = pts.shading_normal(j), ng = pts.geometric_normal(j);
        const Vec3f above = pts.above(j);
        std::size_t bucket = scene_.lights.size();
        for (const DistantLight& light : scene_.distant_lights) {
            const Vec3f l = -light.direction;
            if (dot(ns, l) > 0 && dot(ng, l) > 0) {
                ++s.stats.shadow_rays;
                ShadowQueue& q = s.shadows.per_light[bucket];
                const ShadowQueue::Run run = q.append(1);
                spawn_ray(above, l, offset_, *run.rays);
                *run.owner = i;
                *run.contribution = direct(m, cutoff, light.color * intensity_, ns, l, view);
            }
            ++bucket;
        }
    }

    /// The reflection ray of shading point j (SPD protocol), and its link;
    /// a transmitting point is queued for spawn_refraction.
    void spawn_reflection(std::size_t j, int depth, Scratch& s) const {
        RayTree& tree = s.tree;
        const ShadingPoints& pts = s.points;
        const std::int32_t i = pts.ray(j);
        const SpawnPoint& sp = s.spawn[j];
        const Material& m = scene_.materials[sp.material];
        // SPD protocol (Readme, items 8 and 9): reflective and transmitting
        // surfaces both spawn a reflection ray, weighted by Ks; transmitters
        // also spawn a refraction ray unless total internal reflection occurs,
        // in which case the reflection carries the transmitted share as well.
        if (!(m.ks > 0 || m.transmittance > 0)) return;
        const Vec3f view = pts.view(j), ns = pts.shading_normal(j), ng = pts.geometric_normal(j);
        Vec3f reflected_dir = view - ns * (2.0f * dot(view, ns));
        if (options_.distribution && m.gloss > 0) {
            // Glossy: a direction of the Phong lobe about the mirror direction;
            // one under the surface falls back to the mirror direction.
            const std::uint64_t key = tree.sample[std::size_t(i)];
            const Sample2 u = samples_.get(key / std::uint64_t(samples_.spp()), int(key % std::uint64_t(samples_.spp())),
                                           1 + depth);
            const Vec3f mirror = normalize(reflected_dir);
            const Vec3f d = OrthonormalBasis<float>(mirror).to_world(phong_lobe(m.gloss, u.x, u.y));
            if (dot(d, ng) > 0) reflected_dir = d;
        }
        RayTree::Link& link = tree.links.emplace_back(RayTree::Link{i});
        ++s.stats.reflect_rays;
        link.reflect = tree.add();
        link.ks = m.ks;
        tree.sample[std::size_t(link.reflect)] = tree.sample[std::size_t(i)];
        tree.time[std::size_t(link.reflect)] = tree.time[std::size_t(i)];
        spawn_ray(pts.above(j), reflected_dir, offset_, tree.rays[std::size_t(link.reflect)]);
        if (m.transmittance > 0) {
            link.kt = m.transmittance;
            s.refracting.emplace_back(j, tree.links.size() - 1);
        }
    }

    /// The refraction ray of transmitting shading point j, unless total
    /// internal reflection occurs (Snell's law; entering when the ray met
    /// the outward side).
    void spawn_refraction(std::size_t j, std::size_t link, Scratch& s) const {
        RayTree& tree = s.tree;
        const ShadingPoints& pts = s.points;
        const std::int32_t i = pts.ray(j);
        const SpawnPoint& sp = s.spawn[j];
        const Material& m = scene_.materials[sp.material];
        const Vec3f view = pts.view(j), ns = pts.shading_normal(j), ng = pts.geometric_normal(j);
        const float eta = sp.front ? 1.0f / m.ior : m.ior;
        const float cos_i = -dot(view, ns);
        const float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
        if (!(k >= 0)) return;
        ++s.stats.refract_rays;
        const Vec3f dir = view * eta + ns * (eta * cos_i - std::sqrt(k));
        const std::int32_t child = tree.add();
        tree.sample[std::size_t(child)] = tree.sample[std::size_t(i)];
        tree.time[std::size_t(child)] = tree.time[std::size_t(i)];
        spawn_ray(offset_.offset(sp.p, -ng), dir, offset_, tree.rays[std::size_t(child)]);
        tree.links[link].refract = child;
    }

    /// A cos at or below which phong_power(cos, shine) is exactly +0: it is
    /// +0 once shine * log2(cos) < -125, and its log2 is far more precise than
    /// the margin of 1 below, so skipping the call there gives the same bits.
    /// On mount, whose highlights have a shine of 101, the underflowing calls
    /// were 5% of the render.
    static float specular_cutoff(float shine) {
        if (!(shine > 0)) return 0.0f;
        return std::nextafter(float(std::exp2(-126.0 / double(shine))), 0.0f);
    }

    /// Ambient-free light of one unoccluded light of colour `light_color`
    /// arriving along unit `l`: Lambert plus the Phong highlight.
    static Vec3f direct(const Material& m, float cutoff, const Vec3f& light_color, const Vec3f& ns, const Vec3f& l,
                        const Vec3f& view) {
        const float diffuse = m.kd * dot(ns, l);
        const Vec3f r = ns * (2.0f * dot(ns, l)) - l;  // mirror of l about the normal
        const float rv = std::max(0.0f, -dot(r, view));
        const float specular = m.ks > 0 && rv > cutoff ? m.ks * phong_power(rv, m.shine) : 0.0f;
        return light_color * m.color * diffuse + light_color * specular;
    }

    /// Traces the level's shadow rays as one batch, light by light, and adds
    /// the unoccluded contributions in light order, as the recursion did.
    void trace_shadows(Scratch& s, bool stream) const {
        ShadowBatch& b = s.shadows;
        std::size_t total = 0, queues = 0;
        const ShadowQueue* only = nullptr;
        for (const ShadowQueue& q : b.per_light)
            if (!q.rays.empty()) total += q.rays.size(), ++queues, only = &q;
        if (total == 0) return;
        // One light's rays are traced where they are (the copy was 3% of a
        // Cornell box's render); several lights' are gathered in light order.
        std::span<const Rayf> all;
        if (queues == 1) {
            all = only->rays;
        } else {
            b.all.clear();
            for (const ShadowQueue& q : b.per_light) b.all.insert(b.all.end(), q.rays.begin(), q.rays.end());
            all = b.all;
        }
        b.occluded.resize(total);
        b.times.clear();
        if (timed_)
            for (const ShadowQueue& q : b.per_light)
                for (const std::int32_t owner : q.owner) b.times.push_back(s.tree.time[std::size_t(owner)]);
        if (options_.ray_log) options_.ray_log->add(RayLog::Shadow, all, b.times);
        if (timed_) accel_.occluded_at(options_.secondary_packet, all, b.times, b.occluded);
        else if (stream) accel_.occluded_stream(options_.secondary_packet, all, b.occluded);
        else accel_.occluded_packets(options_.secondary_packet, all, b.occluded);
        std::size_t k = 0;
        for (const ShadowQueue& q : b.per_light)
            for (std::size_t j = 0; j < q.rays.size(); ++j, ++k)
                if (!b.occluded[k]) s.tree.color[std::size_t(q.owner[j])] += q.contribution[j];
    }
};

}  // namespace

namespace {

/// A square of the image in units of 2^-depth pixels, with the colours at
/// its corners (top-left, top-right, bottom-left, bottom-right).
struct Square {
    std::int64_t x, y;  ///< top-left corner, fine units
    std::int64_t size;
    Vec3f c[4];
};

float max_difference(const Square& q) {
    float d = 0;
    for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b)
            for (int ch = 0; ch < 3; ++ch) d = std::max(d, std::fabs(q.c[a][ch] - q.c[b][ch]));
    return d;
}

/// Adaptive supersampling (Whitted 1980's adaptive subdivision, as POV-Ray's
/// +AM2 does it): corners of the pixels first, then every square whose
/// corners differ by the threshold gets its edge midpoints and centre, level
/// by level, each level one batch through the wavefront.
RenderStats render_adaptive(const Scene& scene, const Accel& accel, const WhittedOptions& options, Image& image) {
    const auto start = std::chrono::steady_clock::now();
    WhittedOptions point_options = options;
    point_options.spp = 1;  // one sample per point, keyed by the point
    point_options.sampler = SamplerKind::Random;
    const CameraFrame frame = make_camera_frame(scene.camera, options.width, options.height);
    const WhittedWavefront tracer(scene, accel, point_options);
    const int depth = std::clamp(options.adaptive_depth, 0, 8);
    const std::int64_t fine = std::int64_t(1) << depth;                        // fine units per pixel
    const std::uint64_t row = std::uint64_t(options.width) * std::uint64_t(fine) + 1;  // fine points per row
    const TileGrid grid = render_tiles(scene, options, accel, false);
    PerWorker<Scratch> scratch;
    std::atomic<std::uint64_t> points{0};
    TileProgress progress(std::uint64_t(options.width) * std::uint64_t(options.height), options.progress,
                          options.progress_context);
    image = Image(options.width, options.height);
    for_each_tile(grid, [&](int tile, int slot) {
        Scratch& s = scratch.at(slot);
        const TileGrid::Rect r = grid.rect(tile);
        const int x0 = r.x0, y0 = r.y0, x1 = r.x1, y1 = r.y1;  // named variables: the lambdas below capture them
        // Traces points (fine coordinates) as one batch; colours in s.tree.color.
        std::vector<std::pair<std::int64_t, std::int64_t>> batch;
        const auto trace_points = [&] {
            s.tree.reset(batch.size());
            for (std::size_t i = 0; i < batch.size(); ++i) {
                const auto [fx, fy] = batch[i];
                const std::uint64_t key = std::uint64_t(fy) * row + std::uint64_t(fx);
                const float px = float(double(fx) / double(fine)), py = float(double(fy) / double(fine));
                s.tree.rays[i] = thin_lens_ray(frame, px, py, tracer.lens_sample(key), scene.camera.lens_radius,
                                               scene.camera.focus_distance);
                s.tree.sample[i] = key;
                if (tracer.timed()) s.tree.time[i] = tracer.time_sample(key);
            }
            tracer.trace(batch.size(), s);
            points.fetch_add(batch.size(), std::memory_order_relaxed);
        };
        // Level 0: the tile's pixel corners, shared by neighbouring pixels.
        const int cw = x1 - x0 + 1;
        batch.clear();
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) batch.emplace_back(std::int64_t(x) * fine, std::int64_t(y) * fine);
        trace_points();
        std::vector<Square> squares, next;
        std::vector<Vec3f> sum(std::size_t((x1 - x0) * (y1 - y0)));
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                const std::size_t i = std::size_t((y - y0) * cw + (x - x0));
                squares.push_back({std::int64_t(x) * fine, std::int64_t(y) * fine, fine,
                                   {s.tree.color[i], s.tree.color[i + 1], s.tree.color[i + std::size_t(cw)],
                                    s.tree.color[i + std::size_t(cw) + 1]}});
            }
        const auto settle = [&](const Square& q) {
            const int px = int(q.x / fine) - x0, py = int(q.y / fine) - y0;
            const float w = float(q.size * q.size) / float(fine * fine) * 0.25f;
            sum[std::size_t(py * (x1 - x0) + px)] += (q.c[0] + q.c[1] + q.c[2] + q.c[3]) * w;
        };
        for (int level = 0; !squares.empty(); ++level) {
            batch.clear();
            next.clear();
            for (const Square& q : squares) {
                if (level >= depth || max_difference(q) < options.adaptive_threshold) {
                    settle(q);
                    continue;
                }
                const std::int64_t h = q.size / 2;
                // Top, left, centre, right, bottom midpoints.
                for (const auto& [dx, dy] : {std::pair{h, std::int64_t(0)}, std::pair{std::int64_t(0), h},
                                             std::pair{h, h}, std::pair{q.size, h}, std::pair{h, q.size}})
                    batch.emplace_back(q.x + dx, q.y + dy);
                next.push_back(q);
            }
            if (next.empty()) break;
            trace_points();
            squares.clear();
            for (std::size_t k = 0; k < next.size(); ++k) {
                const Square& q = next[k];
                const Vec3f* m = &s.tree.color[5 * k];  // top, left, centre, right, bottom
                const std::int64_t h = q.size / 2;
                squares.push_back({q.x, q.y, h, {q.c[0], m[0], m[1], m[2]}});
                squares.push_back({q.x + h, q.y, h, {m[0], q.c[1], m[2], m[3]}});
                squares.push_back({q.x, q.y + h, h, {m[1], m[2], q.c[2], m[4]}});
                squares.push_back({q.x + h, q.y + h, h, {m[2], m[3], m[4], q.c[3]}});
            }
        }
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) image.set(x, y, sum[std::size_t((y - y0) * (x1 - x0) + (x - x0))]);
        const std::uint64_t n = std::uint64_t((x1 - x0) * (y1 - y0));
        progress.add(n);
    });
    RenderStats stats;
    scratch.for_each([&](const Scratch& s) { stats += s.stats; });
    stats.samples_per_pixel = double(points) / double(progress.total());
    stats.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

}  // namespace

TileGrid render_tiles(const Scene& scene, const WhittedOptions& options, const Accel& accel,
                      bool one_sample_a_pixel) {
    if (options.tile_size > 0) return {options.width, options.height, options.tile_size};
    std::size_t curved_mirrors = 0;
    for (std::size_t i = 0; i < scene.prims.size(); ++i) {
        const PrimKind kind = scene.prims[i].kind;
        const Material& m = scene.materials[scene.prim_material[i]];
        curved_mirrors += (kind == PrimKind::Sphere || kind == PrimKind::Cone) && (m.ks > 0 || m.transmittance > 0);
    }
    const bool streams = one_sample_a_pixel && accel.supports_stream() && 2 * curved_mirrors >= scene.prims.size();
    if (!streams) return {options.width, options.height, 16};
    // 64 at any thread count: at 2 threads, 32 was faster only while each
    // worker thread faulted its larger scratch memory in page by page (an
    // arena of its own: app/heap_pages.cpp); with one heap, 64 rendered
    // balls 4% and rings 9% faster than 32.
    return {options.width, options.height, 64};
}

RenderStats render_whitted(const Scene& scene, const Accel& accel, const WhittedOptions& options, Image& image) {
    if (options.distribution && options.adaptive_threshold > 0) return render_adaptive(scene, accel, options, image);
    const auto start = std::chrono::steady_clock::now();
    const CameraFrame frame = make_camera_frame(scene.camera, options.width, options.height);
    const WhittedWavefront tracer(scene, accel, options);
    const int spp = options.distribution ? options.spp : 1;
    const TileGrid grid = render_tiles(scene, options, accel, spp == 1);
    PerWorker<Scratch> scratch;
    TileProgress progress(std::uint64_t(options.width) * std::uint64_t(options.height), options.progress,
                          options.progress_context);
    std::optional<Film> own_film;  // Whitted writes the image directly
    Film* film = nullptr;
    if (spp > 1) {
        film = options.film && options.film->has_size(options.width, options.height)
                   ? options.film
                   : &own_film.emplace(options.width, options.height);
    }
    // Every pixel is written, by the tile that holds it: an image of the
    // right size from the caller is kept (the command line makes it before
    // the build, so that its fresh pages are not faulted in on the
    // render's clock).
    if (image.width != options.width || image.height != options.height) image = Image(options.width, options.height);
    // Sampled renders: each tile's part of the noise estimate, summed in
    // tile order at the end.
    std::vector<FilmNoise> tile_noise(film ? std::size_t(grid.count()) : 0);
    for_each_tile(grid, [&](int tile, int slot) {
        Scratch& s = scratch.at(slot);
        grid.pixels(tile, s.pixels);
        // The samples of one pixel are consecutive, so packets of eye rays
        // stay within a block of neighbouring pixels.
        // Samples in chunks, so that a batch stays near kMaxBatch eye rays
        // whatever --spp is (memory grows with the batch's ray tree).
        const int chunk = std::max(1, int(kMaxBatch / s.pixels.size()));
        for (int k0 = 0; k0 < spp; k0 += chunk) {
            const int k1 = std::min(spp, k0 + chunk);
            const std::size_t n = s.pixels.size() * std::size_t(k1 - k0);
            s.tree.reset(n);
            std::size_t i = 0;
            if (!options.distribution) {
                // Through the pixel centres. The frame is copied so that the
                // compiler knows the ray stores cannot change it.
                const CameraFrame f = frame;
                for (const PixelXY& px : s.pixels) {
                    s.tree.rays[i] = camera_ray(f, float(px.x) + 0.5f, float(px.y) + 0.5f);
                    s.tree.sample[i++] = std::uint64_t(px.y) * std::uint64_t(options.width) + std::uint64_t(px.x);
                }
            } else {
                tracer.camera_samples(s.pixels, k0, k1, frame, s);
            }
            tracer.trace(n, s);
            i = 0;
            for (const PixelXY& px : s.pixels) {
                if (spp == 1) {
                    image.set(px.x, px.y, s.tree.color[i++]);  // Whitted: exactly the ray's colour
                    continue;
                }
                film->add(px.x, px.y, std::span(s.tree.color).subspan(i, std::size_t(k1 - k0)));
                i += std::size_t(k1 - k0);
            }
        }
        // The tile's samples are all in: its pixels resolve here, in
        // parallel (after the loop they were 10-16% of a Cornell box's
        // render at 4 samples, on one thread).
        if (film) {
            const auto [x0, y0, x1, y1] = grid.rect(tile);
            tile_noise[std::size_t(tile)] = film->resolve(x0, y0, x1, y1, image);
        }
        progress.add(s.pixels.size());
    });
    RenderStats stats;
    if (film) {
        FilmNoise noise;
        for (const FilmNoise& n : tile_noise) noise += n;
        stats.noise_rms = noise.rms();
    }
    scratch.for_each([&](const Scratch& s) { stats += s.stats; });
    stats.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

void whitted_radiance(const Scene& scene, const Accel& accel, const WhittedOptions& options,
                      std::span<const Rayf> rays, std::span<Vec3f> colors, RenderStats& stats) {
    Scratch s;
    s.tree.reset(rays.size());
    std::copy(rays.begin(), rays.end(), s.tree.rays.begin());
    for (std::size_t i = 0; i < rays.size(); ++i) s.tree.sample[i] = i;
    WhittedWavefront(scene, accel, options).trace(rays.size(), s);
    std::copy(s.tree.color.begin(), s.tree.color.begin() + std::ptrdiff_t(rays.size()), colors.begin());
    stats += s.stats;
}

Vec3f whitted_radiance(const Scene& scene, const Accel& accel, const WhittedOptions& options, const Rayf& ray) {
    Vec3f color;
    RenderStats stats;
    whitted_radiance(scene, accel, options, {&ray, 1}, {&color, 1}, stats);
    return color;
}

}  // namespace raypack
