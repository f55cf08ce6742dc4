#pragma once
// Scenes whose primitives are grouped into closed convex objects, for
// measuring accuracy (`raypack bench --tradeoff`, tests): a ray aimed at the
// boundary of such an object must hit it (else it leaks), and a ray leaving
// its surface outward can never hit the same object again (else it
// self-intersects).
#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace raypack {

/// A scene and, per primitive, the convex object it belongs to.
struct ObjectScene {
    Scene scene;
    std::vector<std::uint32_t> object;  ///< object[prim]
    std::vector<Vec3f> centroid;        ///< a point on the inner side of every face of each object
    std::uint32_t object_count() const { return std::uint32_t(centroid.size()); }
};

/// A closed UV sphere of `segments` x `rings` (poles are fans of
/// `segments` triangles meeting in one vertex): every vertex is computed once
/// and reused, so neighbouring triangles share their edges bit for bit.
void add_uv_sphere_mesh(Scene& scene, const Vec3f& centre, float radius, int segments, int rings,
                        std::uint32_t material);

/// Groups the triangles of `scene` into objects that share edges exactly
/// (two equal vertices; touching at a single vertex does not join), and
/// makes every sphere an object of its own. Centroids are the means of each
/// object's distinct vertices (inside, for convex objects).
ObjectScene group_into_objects(Scene scene);

/// The scene of the leak measure: tessellated spheres at several
/// resolutions (`detail` 0: 8x6, 32x16; 1: also 128x64 and 512x256), one of
/// them far from the origin, plus the SPD tetrahedron gen:tetra:`tetra_size`
/// whose small tetrahedra are closed meshes of four triangles.
ObjectScene leak_test_meshes(int detail, int tetra_size);

/// Spheres, tessellated spheres, a tetrahedron and a floor (two coplanar
/// triangles, one object), all of size ~`scale` around `translation`, with a
/// light and a camera: the scene of the self-intersection measure.
ObjectScene mixed_convex_scene(float scale, const Vec3f& translation);

}  // namespace raypack
