#pragma once
// Placements that move over the shutter (Scene::moving_instances) in a
// 4-wide BVH whose nodes keep two boxes per child, one at the shutter's
// opening and one at its closing; a ray at shutter fraction s tests the
// four boxes interpolated at s in SIMD lanes. This is Embree's linear
// motion BVH (BVH4MB, Woop et al. 2017, "Embree ray tracing kernels:
// overview and new features"), built as a binary SAH tree and collapsed.
// Linear bounds rather than time-segmented nodes: each
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
#include <span>
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

    /// The same for a batch of rays with their fractions, traced as packets
    /// (16 lanes with AVX-512, each lane at its own time) down the tree: a
    /// node's four children are tested for all the packet's lanes in SIMD,
    /// a primitive item for all its lanes in one K x 1 kernel call; lanes
    /// left alone go on ray by ray.
    void intersect(std::span<const Rayf> rays, std::span<const float> fractions, std::span<Hitf> hits) const;
    /// occluded[i] is set to 1 where a moving placement blocks ray i (it
    /// is left as it is elsewhere).
    void occluded(std::span<const Rayf> rays, std::span<const float> fractions, std::span<std::uint8_t> occluded) const;

    std::size_t node_count() const { return wide_.size(); }
    std::size_t bytes() const {
        return wide_.size() * sizeof(WideNode) + items_.size() * sizeof(Item) + order_.size() * sizeof(std::uint32_t);
    }
    std::size_t item_count() const { return items_.size(); }
    int depth() const { return depth_; }

private:
    /// The binary tree of the build. Inner node: count == 0, children at
    /// first and first + 1. Leaf: items order_[first .. first + count).
    struct Node {
        Box3f start, end;
        std::uint32_t first = 0, count = 0;
    };
    /// The traversed tree: four children's boxes at the two ends, SoA.
    /// child[j]: a node index, a leaf (kLeaf | first << 3 | count), or
    /// kEmpty (a slot the lanes mask off).
    static constexpr int kWidth = 4;
    static constexpr std::uint32_t kLeaf = 1u << 31, kEmpty = 0xFFFFFFFFu;
    struct WideNode {
        float lo0[3][kWidth], hi0[3][kWidth], lo1[3][kWidth], hi1[3][kWidth];
        std::uint32_t child[kWidth];
    };

    /// A moving placement (prim == kNoPrim: traced in its object's
    /// structure) or one primitive of its object; boxes at the two ends.
    struct Item {
        Box3f start, end;
        std::uint32_t instance;  ///< into scene_.moving_instances
        std::uint32_t prim;
    };

    /// One ray down the subtree `start` (a child code; 0 is the root).
    template <bool AnyHit>
    bool walk(const Rayf& ray, float s, Hitf& hit, std::uint32_t start = 0) const;
    /// Up to a packet of rays: hits[l] (closest hits) or occluded[l] (AnyHit).
    template <class F, bool AnyHit>
    void walk_packet(const Rayf* rays, const float* fractions, int count, Hitf* hits, std::uint8_t* occluded) const;
    /// The item's own interpolated box (unless `box_tested`: brute force
    /// tests none, a leaf of one item tested it as the leaf's), then its
    /// primitive or object.
    template <bool AnyHit>
    bool test_item(std::uint32_t k, const Rayf& ray, const Vec3f& inv_dir, float s, Hitf& hit, bool box_tested) const;
    void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth);
    /// The wide node over binary node `node`'s (up to four) descendants.
    std::uint32_t collapse(std::uint32_t node);
    /// Bits of the children of `n` whose boxes at s meet the ray's span,
    /// with their entry distances.
    std::uint32_t meet_children(const WideNode& n, const Rayf& ray, const Vec3f& inv_dir, float s, float tfar,
                                float* entry) const;

    const Scene& scene_;
    const ObjectAccels& objects_;
    KernelChoice kernels_;
    bool brute_;
    std::vector<Item> items_;
    std::vector<Node> nodes_;  ///< the build's; emptied once collapsed
    std::vector<WideNode> wide_;
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
