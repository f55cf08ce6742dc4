#include "accel/embree/embree_accel.h"

#ifdef RAYPACK_HAVE_EMBREE

#include "accel/embree/embree_packet_io.h"
#include "accel/embree/embree_packet_types.h"

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace raypack {
namespace {

/// Embree asks for flush-to-zero and denormals-are-zero on every thread that
/// traces (Embree API docs, "Performance Recommendations"). The caller's mode is
/// restored afterwards so that raypack's own IEEE kernels on the same thread
/// keep seeing denormals.
class DenormalsOff {
public:
    DenormalsOff() : ftz_(_MM_GET_FLUSH_ZERO_MODE()), daz_(_MM_GET_DENORMALS_ZERO_MODE()) {
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    }
    ~DenormalsOff() {
        _MM_SET_FLUSH_ZERO_MODE(ftz_);
        _MM_SET_DENORMALS_ZERO_MODE(daz_);
    }
    DenormalsOff(const DenormalsOff&) = delete;
    DenormalsOff& operator=(const DenormalsOff&) = delete;

private:
    unsigned ftz_, daz_;
};

RTCIntersectContext make_context(bool coherent) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    return context;
}

RTCRay to_embree(const Rayf& r) {
    RTCRay ray;
    ray.org_x = r.org.x;
    ray.org_y = r.org.y;
    ray.org_z = r.org.z;
    ray.tnear = r.tnear;
    ray.dir_x = r.dir.x;
    ray.dir_y = r.dir.y;
    ray.dir_z = r.dir.z;
    ray.time = 0.0f;
    ray.tfar = r.tfar;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    return ray;
}

// ---- NFF cones as user geometry ------------------------------------------------
//
// An independent formulation from kernels/cone.h: the ray is moved into the
// cone's own frame, where the surface is x^2 + y^2 = (rb + k z)^2, and the
// quadratic is solved in double precision with the full linear coefficient
// and the cancellation-free root pair q / A, C / q (Press et al., Numerical
// Recipes, 5.6).

/// A unit vector perpendicular to w: w crossed with the coordinate axis it is
/// least aligned with.
Vec3d perpendicular(const Vec3d& w) {
    const Vec3d a = std::fabs(w.x) <= std::fabs(w.y) && std::fabs(w.x) <= std::fabs(w.z) ? Vec3d{1, 0, 0}
                    : std::fabs(w.y) <= std::fabs(w.z)                                  ? Vec3d{0, 1, 0}
                                                                                        : Vec3d{0, 0, 1};
    return normalize(cross(w, a));
}

EmbreeCone make_cone(const Scene& scene, std::size_t i) {
    EmbreeCone c;
    c.base = Vec3d(scene.cones.base[i]);
    const Vec3d axis = Vec3d(scene.cones.apex[i]) - c.base;
    c.h = length(axis);
    c.w = axis / c.h;
    c.u = perpendicular(c.w);
    c.v = cross(c.w, c.u);
    c.rb = double(scene.cones.base_radius[i]);
    c.k = (double(scene.cones.apex_radius[i]) - c.rb) / c.h;
    return c;
}

struct ConeHit {
    double t, z;
    Vec3d normal;  ///< world space, unnormalised
};

/// Nearest crossing of the open truncated cone within [tnear, tfar].
bool cone_hit(const EmbreeCone& c, const Vec3d& org, const Vec3d& dir, double tnear, double tfar, ConeHit& hit) {
    const Vec3d q = org - c.base;
    const Vec3d o{dot(q, c.u), dot(q, c.v), dot(q, c.w)};
    const Vec3d d{dot(dir, c.u), dot(dir, c.v), dot(dir, c.w)};
    const double ro = c.rb + c.k * o.z;  // radius at the origin's height
    const double A = d.x * d.x + d.y * d.y - c.k * c.k * d.z * d.z;
    const double B = 2.0 * (o.x * d.x + o.y * d.y - c.k * ro * d.z);
    const double C = o.x * o.x + o.y * o.y - ro * ro;
    double roots[2];
    int count = 0;
    if (A == 0.0) {  // ray parallel to a generator line: at most one crossing
        if (B == 0.0) return false;
        roots[count++] = -C / B;
    } else {
        const double disc = B * B - 4.0 * A * C;
        if (!(disc >= 0.0)) return false;
        const double qq = -0.5 * (B + std::copysign(std::sqrt(disc), B));
        if (qq == 0.0) {
            roots[count++] = 0.0;
        } else {
            roots[0] = qq / A;
            roots[1] = C / qq;
            if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
            count = 2;
        }
    }
    for (int i = 0; i < count; ++i) {
        const double t = roots[i];
        if (!(t >= tnear && t <= tfar)) continue;
        const double z = o.z + t * d.z;
        const double r = c.rb + c.k * z;
        if (z < 0.0 || z > c.h || r < 0.0) continue;  // beyond the ends or on the mirrored nappe
        const double x = o.x + t * d.x, y = o.y + t * d.y;
        hit.t = t;
        hit.z = z;
        hit.normal = c.u * x + c.v * y - c.w * (c.k * r);
        return true;
    }
    return false;
}

void cone_bounds(const RTCBoundsFunctionArguments* args) {
    const EmbreeCone& c = static_cast<const EmbreeCone*>(args->geometryUserPtr)[args->primID];
    // Each end is a disc of radius r perpendicular to w: its extent along
    // world axis a is r sqrt(1 - w_a^2). Round outwards to float.
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        const double across = std::sqrt(std::max(0.0, 1.0 - c.w[a] * c.w[a]));
        const double r_apex = c.rb + c.k * c.h;
        const double e0 = c.base[a], e1 = c.base[a] + c.w[a] * c.h;
        lo[a] = std::min(e0 - c.rb * across, e1 - r_apex * across);
        hi[a] = std::max(e0 + c.rb * across, e1 + r_apex * across);
    }
    RTCBounds* b = args->bounds_o;
    const float inf = std::numeric_limits<float>::infinity();
    b->lower_x = std::nextafter(float(lo[0]), -inf);
    b->lower_y = std::nextafter(float(lo[1]), -inf);
    b->lower_z = std::nextafter(float(lo[2]), -inf);
    b->upper_x = std::nextafter(float(hi[0]), inf);
    b->upper_y = std::nextafter(float(hi[1]), inf);
    b->upper_z = std::nextafter(float(hi[2]), inf);
}

// Embree calls these with N = 1 from rtcIntersect1 and with N up to the
// packet width from rtcIntersect4/8/16 (valid[i] = -1 for an active lane).
void cone_intersect(const RTCIntersectFunctionNArguments* args) {
    const unsigned n = args->N;
    const EmbreeCone& c = static_cast<const EmbreeCone*>(args->geometryUserPtr)[args->primID];
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, n);
    RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, n);
    for (unsigned i = 0; i < n; ++i) {
        if (!args->valid[i]) continue;
        const Vec3d org{RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i)};
        const Vec3d dir{RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i)};
        ConeHit h;
        if (!cone_hit(c, org, dir, RTCRayN_tnear(ray, n, i), RTCRayN_tfar(ray, n, i), h)) continue;
        RTCRayN_tfar(ray, n, i) = float(h.t);
        RTCHitN_Ng_x(hit, n, i) = float(h.normal.x);
        RTCHitN_Ng_y(hit, n, i) = float(h.normal.y);
        RTCHitN_Ng_z(hit, n, i) = float(h.normal.z);
        RTCHitN_u(hit, n, i) = float(h.z / c.h);  // like raypack: axial fraction from the base
        RTCHitN_v(hit, n, i) = 0.0f;
        RTCHitN_primID(hit, n, i) = args->primID;
        RTCHitN_geomID(hit, n, i) = args->geomID;
        RTCHitN_instID(hit, n, i, 0) = args->context->instID[0];
    }
}

void cone_occluded(const RTCOccludedFunctionNArguments* args) {
    const unsigned n = args->N;
    const EmbreeCone& c = static_cast<const EmbreeCone*>(args->geometryUserPtr)[args->primID];
    RTCRayN* ray = args->ray;
    for (unsigned i = 0; i < n; ++i) {
        if (!args->valid[i]) continue;
        const Vec3d org{RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i)};
        const Vec3d dir{RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i)};
        ConeHit h;
        if (cone_hit(c, org, dir, RTCRayN_tnear(ray, n, i), RTCRayN_tfar(ray, n, i), h))
            RTCRayN_tfar(ray, n, i) = -std::numeric_limits<float>::infinity();
    }
}

static_assert(alignof(RTCRayHit4) >= 16 && alignof(RTCRayHit8) >= 32 && alignof(RTCRayHit16) >= 64);

}  // namespace

EmbreeOptions embree_options(bool robust, const std::string& quality) {
    EmbreeOptions options;
    options.robust = robust;
    if (quality == "low") options.quality = RTC_BUILD_QUALITY_LOW;
    else if (quality == "medium") options.quality = RTC_BUILD_QUALITY_MEDIUM;
    else if (quality == "high") options.quality = RTC_BUILD_QUALITY_HIGH;
    else throw std::invalid_argument("unknown Embree build quality '" + quality + "' (expected low|medium|high)");
    return options;
}

const char* embree_quality_name(RTCBuildQuality quality) {
    switch (quality) {
        case RTC_BUILD_QUALITY_LOW: return "low";
        case RTC_BUILD_QUALITY_HIGH: return "high";
        default: return "medium";
    }
}

bool EmbreeAccel::memory_monitor(void* self, ssize_t bytes, bool /*post*/) {
    static_cast<EmbreeAccel*>(self)->allocated_.fetch_add(std::int64_t(bytes), std::memory_order_relaxed);
    return true;
}

void EmbreeAccel::on_error(void* self, RTCError code, const char* message) {
    auto* me = static_cast<EmbreeAccel*>(self);
    const std::lock_guard<std::mutex> lock(me->error_mutex_);
    if (me->first_error_.empty())
        me->first_error_ = "error " + std::to_string(int(code)) + (message ? std::string(": ") + message : "");
}

void EmbreeAccel::fail(const std::string& what) const {
    std::string detail;
    {
        const std::lock_guard<std::mutex> lock(error_mutex_);
        detail = first_error_;
    }
    throw std::runtime_error("embree: " + what + (detail.empty() ? "" : " (" + detail + ")"));
}

EmbreeAccel::EmbreeAccel(const Scene& scene, EmbreeOptions options) {
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error("embree: rtcNewDevice failed (error " +
                                           std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device_, &EmbreeAccel::on_error, this);
    rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeAccel::memory_monitor, this);
    // Timed from the scene on, like our builders: an application creates
    // the device once, and pays the scene set-up and commit per scene
    // (build_accel keeps this time instead of its own).
    options_ = options;
    const auto start = std::chrono::steady_clock::now();
    try {
        build(scene, options);
    } catch (...) {
        // The destructor does not run for a constructor that throws.
        if (scene_) rtcReleaseScene(scene_);
        rtcReleaseDevice(device_);
        throw;
    }
    const auto stop = std::chrono::steady_clock::now();
    stats_.name = options.robust ? "embree-robust" : "embree";
    native_[0] = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED) != 0;
    native_[1] = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
    native_[2] = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0;
    // The builder text says which packet widths this Embree traces natively
    // (an emulated width is split into single rays inside Embree).
    stats_.builder = std::string(options.robust ? "robust" : "fast") + " mode, " +
                     embree_quality_name(options.quality) + " quality, packets 4/8/16 ";
    for (int k = 0; k < 3; ++k) stats_.builder += std::string(k ? "/" : "") + (native_[k] ? "native" : "emulated");
    stats_.build_ms = std::chrono::duration<double, std::milli>(stop - start).count();
    const std::int64_t bytes = allocated_.load();
    stats_.bytes = bytes > 0 ? std::size_t(bytes) : 0;  // geometry buffers included
}

void EmbreeAccel::build(const Scene& scene, const EmbreeOptions& options) {
    // The comparison is meaningless if this build of Embree culls back faces
    // (raypack's triangles are two-sided) or lacks a primitive type.
    if (rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED) ||
        rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_BACKFACE_CULLING_CURVES_ENABLED))
        fail("this build culls back faces; raypack's primitives are two-sided");
    if ((scene.spheres.size() && !rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_POINT_GEOMETRY_SUPPORTED)) ||
        (scene.cones.size() && !rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_USER_GEOMETRY_SUPPORTED)))
        fail("this build lacks point or user geometry");
    if (scene.placements())
        fail("the scene has instances, which the Embree backend does not trace (raypack's own structures do)");
    if (!scene.height_fields.empty())
        fail("the scene has height fields, which the Embree backend does not trace (raypack's own structures do)");

    scene_ = rtcNewScene(device_);
    // Fast mode is Embree's default and its best speed; robust mode avoids
    // optimisations that can lose hits at shared edges (Embree API,
    // rtcSetSceneFlags). Both are offered; neither is raypack's to choose.
    rtcSetSceneFlags(scene_, options.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(scene_, options.quality);

    // Per-kind index -> global number, inverted from scene.prims.
    std::vector<std::uint32_t> sphere_global(scene.spheres.size()), tri_global(scene.triangles.size()),
        cone_global(scene.cones.size());
    for (std::uint32_t g = 0; g < scene.prims.size(); ++g) {
        const PrimRef ref = scene.prims[g];
        switch (ref.kind) {
            case PrimKind::Sphere: sphere_global[ref.index] = g; break;
            case PrimKind::Triangle: tri_global[ref.index] = g; break;
            case PrimKind::Cone: cone_global[ref.index] = g; break;
            case PrimKind::HeightField:
            case PrimKind::Instance: break;  // refused above
        }
    }
    auto attach = [&](RTCGeometry geom, std::vector<std::uint32_t>&& globals) {
        rtcSetGeometryBuildQuality(geom, options.quality);
        rtcCommitGeometry(geom);
        const unsigned id = rtcAttachGeometry(scene_, geom);
        rtcReleaseGeometry(geom);
        if (id >= to_global_.size()) to_global_.resize(id + 1);
        to_global_[id] = std::move(globals);
    };

    // Triangles, unindexed: vertices 3i, 3i+1, 3i+2 (Embree's u, v are the
    // weights of the second and third vertex, as in raypack).
    if (const std::size_t n = scene.triangles.size()) {
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
        auto* idx = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n));
        if (!v || !idx) fail("cannot allocate triangle buffers");
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3f* p[3] = {&scene.triangles.p0[i], &scene.triangles.p1[i], &scene.triangles.p2[i]};
            for (int k = 0; k < 3; ++k) {
                v[9 * i + 3 * k + 0] = p[k]->x;
                v[9 * i + 3 * k + 1] = p[k]->y;
                v[9 * i + 3 * k + 2] = p[k]->z;
                idx[3 * i + k] = unsigned(3 * i + k);
            }
        }
        attach(geom, std::move(tri_global));
    }

    // Spheres: one point (x, y, z, r) each.
    if (const std::size_t n = scene.spheres.size()) {
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        auto* v = static_cast<float*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), n));
        if (!v) fail("cannot allocate sphere buffer");
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3f c = scene.spheres.center[i];
            v[4 * i + 0] = c.x;
            v[4 * i + 1] = c.y;
            v[4 * i + 2] = c.z;
            v[4 * i + 3] = scene.spheres.radius[i];
        }
        attach(geom, std::move(sphere_global));
    }

    // NFF cones as user geometry. Embree 3.13.5's RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE
    // has the right surface (radius linear along the axis, caps removable by
    // setting both RTC_CURVE_FLAG_NEIGHBOR_* flags), but its intersector
    // (coneline_intersector.h) leaves |dir|^2 out of the t^2 coefficient, so
    // it is only correct for unit directions, and raypack's camera and shadow
    // rays are not unit. Reproducer: cylinder (-6.75319, 17.7447, 6) to
    // (-6.75319, 18.8391, 6), radius 0.07412; ray org (-1, -2.61313, 0.5) dir
    // (-0.295867, 1, 0.309016): Embree reports t = 20.546, yet the ray stays
    // more than 0.85 from the axis along the whole segment; the same ray with
    // its direction normalised misses.
    if (const std::size_t n = scene.cones.size()) {
        cones_.resize(n);
        for (std::size_t i = 0; i < n; ++i) cones_[i] = make_cone(scene, i);
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geom, unsigned(n));
        rtcSetGeometryUserData(geom, cones_.data());
        rtcSetGeometryBoundsFunction(geom, &cone_bounds, nullptr);
        rtcSetGeometryIntersectFunction(geom, &cone_intersect);
        rtcSetGeometryOccludedFunction(geom, &cone_occluded);
        attach(geom, std::move(cone_global));
    }

    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) fail("scene build failed");

    // Where each geometry's primitives have consecutive global numbers (one
    // kind of primitive, or kinds defined in runs), a hit's number is
    // base + primID, computed for a whole packet at once.
    consecutive_ = to_global_.size() <= base_.size();
    for (std::size_t g = 0; g < to_global_.size() && consecutive_; ++g) {
        base_[g] = to_global_[g].empty() ? 0 : to_global_[g][0];
        for (std::size_t i = 0; i < to_global_[g].size() && consecutive_; ++i)
            consecutive_ = to_global_[g][i] == base_[g] + std::uint32_t(i);
    }
}

EmbreeAccel::~EmbreeAccel() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

// Embree 3 reads the coherent flag only in its packet and stream paths, so
// single rays take the default context.
void EmbreeAccel::intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const {
    const DenormalsOff ftz;
    RTCIntersectContext context = make_context(false);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        RTCRayHit rh;
        rh.ray = to_embree(rays[i]);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene_, &context, &rh);
        Hitf hit;
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            hit.t = rh.ray.tfar;
            hit.prim = to_global_[rh.hit.geomID][rh.hit.primID];
            hit.u = rh.hit.u;
            hit.v = rh.hit.v;
        }
        hits[i] = hit;
    }
}

void EmbreeAccel::occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const {
    const DenormalsOff ftz;
    RTCIntersectContext context = make_context(false);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        RTCRay ray = to_embree(rays[i]);
        rtcOccluded1(scene_, &context, &ray);
        // Embree marks an occluded ray by setting tfar to -inf.
        occluded[i] = ray.tfar == -std::numeric_limits<float>::infinity() ? 1 : 0;
    }
}

bool EmbreeAccel::native_packet(int width) const {
    switch (width) {
        case 1: return true;
        case 4: return native_[0];
        case 8: return native_[1];
        case 16: return native_[2];
        default: return false;
    }
}

/// Whether a packet runs in the coherent context: its rays share one origin
/// (camera rays; the property raypack's default configuration keys on),
/// unless the options fix the context.
bool EmbreeAccel::coherent(bool one_origin) const {
    switch (options_.context) {
        case EmbreeContext::Coherent: return true;
        case EmbreeContext::Incoherent: return false;
        default: return one_origin;
    }
}

template <int K>
void EmbreeAccel::intersect_k(std::span<const Rayf> rays, std::span<Hitf> hits) const {
    const DenormalsOff ftz;
    typename EmbreePacket<K>::RayHit rh;
    embree_io::set_constant_fields<K>(rh.ray);
    alignas(64) int valid[K];
    for (int i = 0; i < K; ++i) valid[i] = -1;
    for (std::size_t first = 0; first < rays.size(); first += K) {
        const int n = int(std::min<std::size_t>(K, rays.size() - first));
        bool one_origin;
        if (n == K) {
            one_origin = embree_io::load_full<K>(rays.data() + first, rh.ray);
        } else {  // the last, partial packet: lanes past the end repeat the last ray, masked off
            one_origin = false;
            for (int i = 0; i < K; ++i) {
                embree_io::set_lane(rh.ray, i, rays[first + std::size_t(std::min(i, n - 1))]);
                valid[i] = i < n ? -1 : 0;
            }
        }
        embree_io::clear_hits<K>(rh.hit);
        RTCIntersectContext context = make_context(coherent(one_origin));
        EmbreePacket<K>::intersect(valid, scene_, &context, &rh);
        embree_io::store_hits<K>(rh, n, base_.data(), consecutive_, to_global_, hits.data() + first);
    }
}

template <int K>
void EmbreeAccel::occluded_k(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const {
    const DenormalsOff ftz;
    typename EmbreePacket<K>::Ray ray;
    embree_io::set_constant_fields<K>(ray);
    alignas(64) int valid[K];
    for (int i = 0; i < K; ++i) valid[i] = -1;
    for (std::size_t first = 0; first < rays.size(); first += K) {
        const int n = int(std::min<std::size_t>(K, rays.size() - first));
        bool one_origin;
        if (n == K) {
            one_origin = embree_io::load_full<K>(rays.data() + first, ray);
        } else {
            one_origin = false;
            for (int i = 0; i < K; ++i) {
                embree_io::set_lane(ray, i, rays[first + std::size_t(std::min(i, n - 1))]);
                valid[i] = i < n ? -1 : 0;
            }
        }
        RTCIntersectContext context = make_context(coherent(one_origin));
        EmbreePacket<K>::occluded(valid, scene_, &context, &ray);
        embree_io::store_occluded<K>(ray, n, occluded.data() + first);
    }
}

// Packets whose rays share one origin run in Embree's coherent context,
// others in its default incoherent one (coherent() above).
void EmbreeAccel::intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    switch (width) {
        case 4: return intersect_k<4>(rays, hits);
        case 8: return intersect_k<8>(rays, hits);
        case 16: return intersect_k<16>(rays, hits);
        default: return intersect(rays, hits);
    }
}

void EmbreeAccel::occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded_out) const {
    switch (width) {
        case 4: return occluded_k<4>(rays, occluded_out);
        case 8: return occluded_k<8>(rays, occluded_out);
        case 16: return occluded_k<16>(rays, occluded_out);
        default: return occluded(rays, occluded_out);
    }
}

}  // namespace raypack

#endif  // RAYPACK_HAVE_EMBREE
