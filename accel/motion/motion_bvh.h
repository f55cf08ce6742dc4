#pragma once
// Placements that move over the shutter (Scene::moving_instances) in a
// binary BVH whose nodes keep two boxes, one at the shutter's opening and
// one at its closing; a ray at shutter fraction s tests the box
// interpolated at s. This is Embree's linear motion BVH (BVH4MB, Woop et
// al. 2017, "Embree ray tracing kernels: overview and new features") in
// binary form. Linear bounds rather than time-segmented nodes: each
// placement here moves along one linear segment (NFF `move`, or `inst`
// with two matrices), every point of it on a straight line, so the
// interpolated end boxes hold it at every time and one tree serves the
// whole shutter; time segments pay when motion has many steps.
//
// Each placement is traced in its object's structure (built once, shared
// with the static placements) after the ray goes to object space with the
// inverse of the matrix interpolated at the ray's time.
#include <cstdint>
#include <vector>

#include "accel/prims/instance_prims.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

class MotionBvh {
public:
    /// Over scene.moving_instances, whose objects' structures are `objects`.
    /// `brute`: no tree and no box test, every placement for every ray (the
    /// oracle's answer at the ray's time).
    MotionBvh(const Scene& scene, const ObjectAccels& objects, bool brute);

    /// Closest hit of `ray` at shutter fraction `s` among the moving
    /// placements, if closer than hit (when found) and within the ray's
    /// span: hit is replaced, its id the scene's hit id.
    void intersect(const Rayf& ray, float s, Hitf& hit) const;
    /// Whether a moving placement blocks the ray's span at fraction `s`.
    bool occluded(const Rayf& ray, float s) const;

    std::size_t node_count() const { return nodes_.size(); }
    std::size_t bytes() const { return nodes_.size() * sizeof(Node) + order_.size() * sizeof(std::uint32_t); }
    int depth() const { return depth_; }

private:
    /// Inner node: count == 0, children at first and first + 1. Leaf:
    /// placements order_[first .. first + count).
    struct Node {
        Box3f start, end;
        std::uint32_t first = 0, count = 0;
    };

    template <bool AnyHit>
    bool walk(const Rayf& ray, float s, Hitf& hit) const;
    /// The placement's own interpolated box, then its object.
    template <bool AnyHit>
    bool test_placement(std::uint32_t k, const Rayf& ray, const Vec3f& inv_dir, float s, Hitf& hit) const;
    void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth);

    const Scene& scene_;
    const ObjectAccels& objects_;
    bool brute_;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> order_;  ///< indices into scene_.moving_instances
    int depth_ = 0;
};

/// The box (1 - s) a + s b, grown by a few ULPs of its coordinates so that
/// the rounding of the interpolation never cuts off what it bounds.
Box3f interpolate_box(const Box3f& a, const Box3f& b, float s);

}  // namespace raypack
