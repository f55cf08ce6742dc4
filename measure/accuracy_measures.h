#pragma once
// The errors a speed-for-accuracy choice causes, each counted against a
// definition that admits no excuse (docs/accuracy.md):
// leaks through closed meshes and spheres, t error in ULPs against a double
// reference, self-intersections of secondary rays, image error against a
// double-precision reference render.
#include <cstdint>
#include <vector>

#include "accel/accel.h"
#include "measure/closed_meshes.h"
#include "render/image.h"
#include "render/ray_offset.h"
#include "render/whitted.h"

namespace raypack {

/// Rays that must hit a closed object, and those that did not.
struct LeakCounts {
    std::uint64_t vertex_rays = 0, vertex_leaks = 0;  ///< from outside, at a triangle corner
    std::uint64_t edge_rays = 0, edge_leaks = 0;      ///< from outside, at a point of a triangle edge
    std::uint64_t inside_rays = 0, inside_leaks = 0;  ///< from inside, at a corner or an edge point
    std::uint64_t rays() const { return vertex_rays + edge_rays + inside_rays; }
    std::uint64_t leaks() const { return vertex_leaks + edge_leaks + inside_leaks; }
};

/// `ray_count` rays at the triangle corners and edge points of every closed
/// convex mesh of `meshes` (edge points: a + s (b - a) with s uniform, as close
/// to the edge as float allows), each at t = 1. With q a point inside the
/// mesh (its centroid moved by up to a fifth of its size): a quarter of the
/// rays start at q; the others start outside, at target + k (target - q)
/// with k in [1, 3], so that they enter the mesh at the target and head for
/// q (a ray merely grazing a silhouette vertex may miss correctly; these
/// cannot). A leak: no hit before t = 1.001 (from q) or before halfway from
/// the target to q (from outside, t = 1 + 0.5 / k). Deterministic for a
/// given seed, whatever the thread count.
LeakCounts count_mesh_leaks(const ObjectScene& meshes, const Accel& accel, std::uint64_t ray_count,
                            std::uint64_t seed = 1);

/// Spheres of radius 1e-3 to 1e3, centres up to 1e4 from the origin.
ObjectScene leak_test_spheres();
/// `ray_count` rays from random points inside the spheres of `spheres`
/// (down to 2^-20 of the radius from the surface), in random directions;
/// a ray leaks when it finds no hit. Counted as inside_rays.
LeakCounts count_sphere_leaks(const ObjectScene& spheres, const Accel& accel, std::uint64_t ray_count,
                              std::uint64_t seed = 1);

/// Distribution of |t_float - t_reference| in ULPs of float.
struct UlpError {
    std::uint64_t rays = 0;    ///< rays both found on the aimed-at primitive
    std::uint64_t missed = 0;  ///< rays the reference hits and the tested kernel misses
    double median = 0, p99 = 0, max = 0;
};

/// Rays at random interior points of every primitive of `kind` in `scene`,
/// from log-uniform distances of 2 to 1e4 times the primitive's size; the
/// tested kernel (`kernels`, float) against the same primitive in double
/// with the watertight and precise tests, rounded to float.
UlpError t_error_ulps(const Scene& scene, PrimKind kind, KernelChoice kernels, std::uint64_t ray_count,
                      std::uint64_t seed = 1);

/// Secondary rays that found the object they left.
struct SelfIntersections {
    std::uint64_t shadow_rays = 0, shadow_self = 0;
    /// Shadow rays whose answer (occluded or not) differs from the reference:
    /// from the hit point itself, every primitive but those of the object left.
    /// Counts self-intersections and also offsets that jump past an occluder.
    std::uint64_t shadow_wrong = 0;
    std::uint64_t reflect_rays = 0, reflect_self = 0;
    std::uint64_t rays() const { return shadow_rays + reflect_rays; }
    std::uint64_t self() const { return shadow_self + reflect_self; }
};

/// From each camera-ray hit (width x height through the scene's camera,
/// closest hits by `accel`) on the outside of a convex object: a shadow ray
/// toward the first light (when it lies on the outer side) and a mirror
/// reflection about the geometric normal, both leaving by `policy`. Both
/// point away from a convex object, so finding any primitive of the same
/// object (closest hit, shadow rays up to the light) is a self-intersection.
/// The reference shadow answer is traced from the accurate hit point with no
/// offset by `accel`, stepping past hits on the object left (at most 4).
SelfIntersections count_self_intersections(const ObjectScene& scene, const Accel& accel, OffsetPolicy policy,
                                           int width, int height);

/// Whitted render of `scene` (options as given) whose every intersection is
/// the brute-force oracle's in double precision with the watertight and
/// precise tests; shading stays in float.
Image render_double_reference(const Scene& scene, const WhittedOptions& options);

struct ImageError {
    double psnr_db = 0;             ///< over RGB clamped to [0, 1]; +inf when identical
    double differing_fraction = 0;  ///< pixels where a channel differs by more than 1/255
};
ImageError image_error(const Image& test, const Image& reference);

}  // namespace raypack
