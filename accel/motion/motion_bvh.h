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
// The tree's items are of two kinds. A placement whose object is placed
// only once and places nothing itself (every `move` group) contributes its
// primitives, each with its own moving box: motion-blurred geometry, as
// Embree puts moving triangles in its motion BVH. Any other placement is
// one item traced in its object's structure (built once, shared with the
// static placements). Either way the ray goes to object space with the
// inverse of the matrix interpolated at the ray's time.
#include <cstdint>
#include <vector>

#include "accel/kernel_choice.h"
#include "accel/prims/instance_prims.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

class MotionBvh {
public:
    /// Over scene.moving_instances, whose objects' structures are `objects`.
    /// `brute`: no tree and no box test, every placement for every ray (the
    /// oracle's answer at the ray's time).
    MotionBvh(const Scene& scene, const ObjectAccels& objects, const KernelChoice& kernels, bool brute);

    /// Closest hit of `ray` at shutter fraction `s` among the moving
    /// placements, if closer than hit (when found) and within the ray's
    /// span: hit is replaced, its id the scene's hit id.
    void intersect(const Rayf& ray, float s, Hitf& hit) const;
    /// Whether a moving placement blocks the ray's span at fraction `s`.
    bool occluded(const Rayf& ray, float s) const;

    std::size_t node_count() const { return nodes_.size(); }
    std::size_t bytes() const {
        return nodes_.size() * sizeof(Node) + items_.size() * sizeof(Item) + order_.size() * sizeof(std::uint32_t);
    }
    std::size_t item_count() const { return items_.size(); }
    int depth() const { return depth_; }

private:
    /// Inner node: count == 0, children at first and first + 1. Leaf:
    /// placements order_[first .. first + count).
    struct Node {
        Box3f start, end;
        std::uint32_t first = 0, count = 0;
    };

    /// A moving placement (prim == kNoPrim: traced in its object's
    /// structure) or one primitive of its object; boxes at the two ends.
    struct Item {
        Box3f start, end;
        std::uint32_t instance;  ///< into scene_.moving_instances
        std::uint32_t prim;
    };

    template <bool AnyHit>
    bool walk(const Rayf& ray, float s, Hitf& hit) const;
    /// The item's own interpolated box, then its primitive or object.
    template <bool AnyHit>
    bool test_item(std::uint32_t k, const Rayf& ray, const Vec3f& inv_dir, float s, Hitf& hit) const;
    void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth);

    const Scene& scene_;
    const ObjectAccels& objects_;
    KernelChoice kernels_;
    bool brute_;
    std::vector<Item> items_;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> order_;  ///< item indices, in tree order
    int depth_ = 0;
};

/// Boxes a and b (of one thing at the shutter's two ends) each grown by a
/// few ULPs of both, so that lerp_box's rounding never cuts off what the
/// exact interpolation bounds; done once, when the tree is built.
void pad_for_lerp(Box3f& a, Box3f& b);

/// (1 - s) a + s b, corner by corner.
inline Box3f lerp_box(const Box3f& a, const Box3f& b, float s) {
    const float r = 1.0f - s;
    return {{r * a.lo.x + s * b.lo.x, r * a.lo.y + s * b.lo.y, r * a.lo.z + s * b.lo.z},
            {r * a.hi.x + s * b.hi.x, r * a.hi.y + s * b.hi.y, r * a.hi.z + s * b.hi.z}};
}

}  // namespace raypack
