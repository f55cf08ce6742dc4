#include "accel/octree/octree_packet.h"

#include <array>
#include <bit>
#include <limits>

#include "accel/cell_kernel_variants.h"
#include "accel/group_box_culling.h"
#include "accel/outside_prims.h"
#include "accel/ray_box_interval.h"
#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "accel/packet_mailbox.h"
#include "accel/packet_ties.h"
#include "kernels/aabb.h"
#include "kernels/ray_packet.h"

namespace raypack {
namespace {

template <class F>
RAYPACK_INLINE F max3(const F& a, const F& b, const F& c) { return vmax(vmax(a, b), c); }
template <class F>
RAYPACK_INLINE F min3(const F& a, const F& b, const F& c) { return vmin(vmin(a, b), c); }

/// An inner node of the packet walk: each lane's slab parameters, the lanes
/// that entered it, and the children left to try (mirrored numbering, bit
/// c: child c; the node's empty children are never tried). The parameters
/// are stored by half, so that a child's are loads indexed by its bits: along
/// axis k the lower half spans [t0, tm] and the upper one [tm, t1], so
/// enter[k][h] / leave[k][h] bound half h (tm is stored twice). Chosen by
/// address instead of by pointer selects, a child cost 10 fewer instructions.
template <int K>
struct PacketFrame {
    vfloat<K> enter[3][2], leave[3][2];
    vmask<K> active;
    std::uint32_t children;
    std::uint32_t left;

    /// The node's parameters from its slabs' t0 and t1 along axis k.
    RAYPACK_INLINE void set_axis(int k, const vfloat<K>& t0, const vfloat<K>& t1) {
        enter[k][0] = t0;
        leave[k][0] = enter[k][1] = vfloat<K>(0.5f) * (t0 + t1);
        leave[k][1] = t1;
    }
};

/// Child c's parameters in a frame's enter and leave arrays, flattened:
/// axis k's half is bit 2 - k of c.
constexpr std::uint8_t kHalfIndex[8][3] = {
    {0, 2, 4}, {0, 2, 5}, {0, 3, 4}, {0, 3, 5}, {1, 2, 4}, {1, 2, 5}, {1, 3, 4}, {1, 3, 5},
};

/// bits' children in mirrored numbering, for each mirroring mask a: entry
/// [a][bits] has bit c set where bits has bit c ^ a.
constexpr auto kMirroredChildren = [] {
    std::array<std::array<std::uint8_t, 256>, 8> table{};
    for (unsigned a = 0; a < 8; ++a)
        for (unsigned bits = 0; bits < 256; ++bits) {
            unsigned m = 0;
            for (unsigned c = 0; c < 8; ++c)
                if ((bits >> (c ^ a)) & 1u) m |= 1u << c;
            table[a][bits] = std::uint8_t(m);
        }
    return table;
}();

/// `bits` over the children in mirrored numbering: bit c is bit c ^ a of
/// `bits` (a: the mirroring mask).
RAYPACK_INLINE std::uint32_t mirrored_children(std::uint32_t bits, unsigned a) { return kMirroredChildren[a][bits]; }

/// The primitives refs[0, count) against the lanes `m` of one packet:
/// closest hits under the tie rule (accel/packet_ties.h), or occlusion
/// added to `occluded`. The leaf step of both walks below.
template <int K, bool AnyHit, bool Culled = false>
RAYPACK_INLINE void test_refs(const PacketRecordIntersector<vfloat<K>>& isect, const std::uint32_t* refs,
                              std::uint32_t count, vmask<K> m, RayPacket<K>& ray, HitPacket<K>& hit,
                              vmask<K>& occluded, const std::uint32_t* may_hit = nullptr,
                              std::uint32_t packet_bit = 0, PacketMailbox* mailbox = nullptr) {
    for (std::uint32_t k = 0; k < count; ++k) {
        if constexpr (Culled)
            if (!(may_hit[k] & packet_bit)) continue;
        if (mailbox) {  // a test again only finds its own hit: ties go to the lowest primitive
            std::uint32_t& settled = mailbox->settled(refs[k]);
            if (!(mask_bits(m) & ~settled)) continue;
            settled |= mask_bits(m);
        }
        if constexpr (AnyHit) {
            const vmask<K> h = isect.intersect(m, ray, hit, refs[k]);
            occluded = occluded | h;
            m = m & !h;
            if (none(m)) return;
        } else {
            intersect_keeping_lowest<K>(isect, m, ray, hit, refs[k]);
        }
    }
}

// The lanes of `group` share the mirroring mask `a` (their directions' sign
// bits). After mirroring every lane runs towards + on every axis, so a lane
// only ever moves from a child to one with more bits set (the new_node
// table): ascending child numbers are front to back for every lane at once.
// A child is entered by the lanes whose interval [max t0, min t1] meets
// [tnear, tfar], which is the set of children each lane's own walk of
// Revelles et al. visits; tfar shrinks with each hit, so a lane drops out of
// every node behind its closest hit (early termination per lane).
template <int K, bool AnyHit, SlabMethod Slabs>
void walk(const Octree& tree, const PacketRecordIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
          HitPacket<K>& hit, vmask<K> group, unsigned a, vmask<K>& occluded) {
    using F = vfloat<K>;
    using M = vmask<K>;
    const OctreeNode* nodes = tree.nodes.data();
    const std::uint32_t* refs = tree.refs.data();
    // Frames live in the stack array and are never copied: the current node
    // is the top one (12 vectors each, 768 bytes at K = 16).
    PacketFrame<K> stack[kOctreeMaxDepth + 1];
    int sp = 0;
    PacketFrame<K>* f = &stack[0];
    const Vec3<F> lo = splat<F>(tree.cube.lo), hi = splat<F>(tree.cube.hi);
    for (int k = 0; k < 3; ++k) {
        const F od = ray.org[k] * ray.rdir[k];
        const F tlo = plane_distance<Slabs>(lo[k], ray.org[k], ray.rdir[k], od),
                thi = plane_distance<Slabs>(hi[k], ray.org[k], ray.rdir[k], od);
        const bool mirrored = a & (4u >> k);
        f->set_axis(k, mirrored ? thi : tlo, mirrored ? tlo : thi);
    }
    M active = group & (vmax(max3(f->enter[0][0], f->enter[1][0], f->enter[2][0]), ray.tnear) <=
                        vmin(min3(f->leave[0][1], f->leave[1][1], f->leave[2][1]), ray.tfar));
    if (none(active)) return;
    // (Any hit: the lanes of `group` in `occluded` are done.)
    auto test_leaf = [&](const OctreeNode& leaf, M m) {
        test_refs<K, AnyHit>(isect, refs + leaf.first, leaf.count, m, ray, hit, occluded);
    };
    if (nodes[0].is_leaf()) {
        test_leaf(nodes[0], active);
        return;
    }
    f->active = active;
    f->children = nodes[0].first;
    f->left = mirrored_children(nodes[0].occupied(), a);
    for (;;) {
        if (f->left == 0) {
            if (sp == 0) return;
            f = &stack[--sp];
            continue;
        }
        const int c = std::countr_zero(f->left);  // ascending: front to back for every lane
        f->left &= f->left - 1;
        const OctreeNode node = nodes[f->children + (unsigned(c) ^ a)];
        // The child's parameters: named vectors, not arrays (GCC kept arrays
        // of them in memory, six stores a child), at indices from a table
        // (the bits' shifts and masks were 15 instructions a child).
        const std::uint8_t* half = kHalfIndex[c];
        const F* enter = &f->enter[0][0];
        const F* leave = &f->leave[0][0];
        const F x0 = enter[half[0]], y0 = enter[half[1]], z0 = enter[half[2]];
        const F x1 = leave[half[0]], y1 = leave[half[1]], z1 = leave[half[2]];
        M m = f->active & (vmax(max3(x0, y0, z0), ray.tnear) <= vmin(min3(x1, y1, z1), ray.tfar));
        if constexpr (AnyHit) m = m & !occluded;
        if (none(m)) continue;
        if (node.is_leaf()) {
            test_leaf(node, m);
            if constexpr (AnyHit)
                if (all(occluded | !group)) return;
            continue;
        }
        PacketFrame<K>* g = &stack[++sp];
        g->set_axis(0, x0, x1);
        g->set_axis(1, y0, y1);
        g->set_axis(2, z0, z1);
        g->active = m;
        g->children = node.first;
        g->left = mirrored_children(node.occupied(), a);
        f = g;
    }
}

template <int K, bool AnyHit, SlabMethod Slabs>
void trace_packet(const Octree& tree, const PacketRecordIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
                  HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
    using F = vfloat<K>;
    using M = vmask<K>;
    // reciprocal() keeps the sign bit, -0 included: rdir < 0 iff the sign bit of dir is set.
    const M neg[3] = {ray.rdir.x < F(0.0f), ray.rdir.y < F(0.0f), ray.rdir.z < F(0.0f)};
    // One walk per octant present (usually one: coherent packets share their signs).
    M left = valid;
    while (any(left)) {
        const int l = std::countr_zero(mask_bits(left));
        unsigned a = 0;
        M group = left;
        for (int k = 0; k < 3; ++k) {
            const bool n = lane(neg[k], l);
            a |= n ? 4u >> k : 0u;
            group = group & (n ? neg[k] : !neg[k]);
        }
        walk<K, AnyHit, Slabs>(tree, isect, ray, hit, group, a, occluded);
        left = left & !group;
    }
}

#if defined(__AVX2__)
/// Inner nodes of at most this side (a fraction of the root's) clip each
/// packet that enters them to their box, as leaves do: the bounds alone
/// admitted five times the leaves a packet reaches on balls and gears
/// (lanes that found their hit keep the bounds wide while their neighbours
/// go on). Callgrind, camera rays 512 x 512, the whole process against
/// packets alone: never 553 M instructions on balls against 440 alone, 1/100
/// 460 M, 1/25 478 M; gears 1703 / 1627 / 1593 M against 1592 M; teapot 291
/// / 294 / 297 M against 331 M; mount 399 / 403 / 409 M against 464 M.
constexpr float kClipBelow = 1.0f / 64.0f;

/// A leaf that this many packets of a group reach, and of at most
/// kMaxCulledRefs references, first tests its primitives' boxes against
/// the packets (packets_meeting_box). Against none, camera rays 1024 x
/// 1024 (the same build, alternating): tetra 1.21x, balls 1.08x, teapot
/// 1.07x, mount 1.05x, gears 0.95x; from 1, 3 or 8 packets on, within 3% of
/// 2 (8: tetra 0.92x). Leaves of up to 64 references rather than 32 (the
/// deepest leaves hold more than 8): tetra 1.047x, mount 1.030x, balls
/// 1.028x, gears 1.007x, teapot 0.984x; 128: as 64.
constexpr int kMinPacketsToCull = 2;
constexpr std::uint32_t kMaxCulledRefs = 64;

/// A packet whose rays' reciprocal directions differ by more than this
/// factor along an axis walks alone, not in a group: its rays are nearly
/// parallel to a plane of the axes (next to the border of the octant, on
/// camera rays across the image's middle), and its bounds, by intervals of
/// those reciprocals carried down the tree by midpoints, stay as loose in
/// small nodes as at the root, admitting far more nodes than its rays
/// reach. Camera rays 1024 x 1024, groups of 16 packets, against no such
/// rule: gears 1.33x, teapot 0.96x, tetra 0.975x; among 1.1 to 2, 1.25 was
/// best on gears (1.5: 0.97x of it, 1.1: tetra 0.98x).
constexpr float kMaxReciprocalSpread = 1.25f;

/// A node of the group walk: per packet (in lanes), bounds of its lanes'
/// slab parameters, by half as in PacketFrame: lo_* bound every lane's from
/// below, hi_* from above.
template <int G>
struct GroupFrame {
    using PF = vfloat<G>;
    PF lo_enter[3][2], lo_leave[3][2], hi_enter[3][2], hi_leave[3][2];
    std::uint32_t packets;  ///< the packets that entered the node
    std::uint32_t children;
    std::uint32_t left;
    float corner[3];  ///< the node's lowest corner
    float half;       ///< its children's side

    /// The box of child r (real numbering).
    Box3f child_box(unsigned r) const {
        Box3f b;
        for (int k = 0; k < 3; ++k) {
            b.lo[k] = (r >> (2 - k)) & 1u ? corner[k] + half : corner[k];
            b.hi[k] = b.lo[k] + half;
        }
        return b;
    }

    RAYPACK_INLINE void set_axis(int k, const PF& t0_lo, const PF& t1_lo, const PF& t0_hi, const PF& t1_hi) {
        lo_enter[k][0] = t0_lo;
        lo_leave[k][0] = lo_enter[k][1] = PF(0.5f) * (t0_lo + t1_lo);
        lo_leave[k][1] = t1_lo;
        hi_enter[k][0] = t0_hi;
        hi_leave[k][0] = hi_enter[k][1] = PF(0.5f) * (t0_hi + t1_hi);
        hi_leave[k][1] = t1_hi;
    }
};

/// The mirroring mask of a packet's valid lanes, or -1 if they do not share
/// one direction octant (or there are none).
template <int K>
RAYPACK_INLINE int packet_octant(const LoadedPacket<K>& p) {
    const std::uint32_t bits = mask_bits(p.valid);
    if (bits == 0) return -1;
    int a = 0;
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t negative = mask_bits(p.ray.rdir[k] < vfloat<K>(0.0f)) & bits;
        if (negative != 0 && negative != bits) return -1;
        a |= negative != 0 ? 4 >> k : 0;
    }
    return a;
}

// Up to G packets whose rays share one direction octant
// walk the tree together (large packets: Reshetov, Soupikov & Hurley,
// SIGGRAPH 2005; Wald's thesis, 2004), one walk for all of them where each
// packet walks alone. A packet stands for its lanes by the smallest and
// largest of their root slab parameters per axis; the parameters of every
// node below are midpoints, and rounding is monotone, so the midpoints of
// the bounds bound every lane's own (PacketFrame's arithmetic, operation for
// operation). A packet enters a child when its bounds allow one of its
// lanes to (max of the lower entries <= min of the upper exits, within its
// lanes' [tnear, tfar]): every leaf a lane's own walk reaches, and more.
// A packet reaching a leaf (a node of at most OctreeConfig::group_leaf_size
// primitives is one to groups; also a small inner node, kClipBelow) clips its
// lanes to the node's box, widened by twice the placement margin (which
// covers the rounding of a lane's own parameters, octree_build.cpp), and
// the lanes left test the leaf's primitives: each lane tests at least the
// primitives its single ray does and, under the tie rule, keeps the same
// closest hit. Children are taken in ascending mirrored order, front to
// back for every lane of every packet. Returns the packets it leaves to
// walk alone: those not of the first packet's octant, not from one point,
// or whose rays' reciprocal directions spread too far apart
// (kMaxReciprocalSpread).
template <int K, int G, bool AnyHit, SlabMethod Slabs>
std::uint32_t trace_group(const Octree& tree, const PacketRecordIntersector<vfloat<K>>& isect, LoadedPacket<K>* p,
                          int count) {
    using F = vfloat<K>;
    using M = vmask<K>;
    using PF = vfloat<G>;  // one lane per packet
    constexpr float inf = std::numeric_limits<float>::infinity();
    int a = -1;
    std::uint32_t alone = 0;
    for (int q = 0; q < count; ++q) {
        const int octant = packet_octant<K>(p[q]);
        if (octant < 0 || (a >= 0 && octant != a)) alone |= 1u << q;
        else a = octant;
    }
    if (a < 0) return alone;
    const OctreeNode* nodes = tree.nodes.data();
    const std::uint32_t* refs = tree.refs.data();
    alignas(64) float t0_lo[3][G], t0_hi[3][G], t1_lo[3][G], t1_hi[3][G], near_lo[G], far_hi[G];
    // Per packet, for culling a leaf's primitives by their boxes: its rays'
    // origin and reciprocal directions' bounds (packets_meeting_box).
    alignas(64) float org[3][G], r_lo[3][G], r_hi[3][G];
    float g_lo[3] = {inf, inf, inf}, g_hi[3] = {-inf, -inf, -inf};  // every packet's origin (culling_box_pad)
    std::uint32_t up = 0;
    for (int k = 0; k < 3; ++k) up |= a & (4 >> k) ? 0u : 1u << k;
    F non_finite(0.0f);
    M lanes[G];  // per packet: the lanes still traced
    std::uint32_t live = 0;
    const Vec3<F> lo = splat<F>(tree.cube.lo), hi = splat<F>(tree.cube.hi);
    for (int q = 0; q < G; ++q) {
        near_lo[q] = inf, far_hi[q] = -inf;  // a packet that enters nothing
        for (int k = 0; k < 3; ++k)
            t0_lo[k][q] = t0_hi[k][q] = t1_lo[k][q] = t1_hi[k][q] = org[k][q] = r_lo[k][q] = r_hi[k][q] = 0.0f;
        if (q >= count || ((alone >> q) & 1u)) continue;
        const RayPacket<K>& ray = p[q].ray;
        F t0[3], t1[3];
        for (int k = 0; k < 3; ++k) {  // as walk() computes them
            const F od = ray.org[k] * ray.rdir[k];
            const F tlo = plane_distance<Slabs>(lo[k], ray.org[k], ray.rdir[k], od),
                    thi = plane_distance<Slabs>(hi[k], ray.org[k], ray.rdir[k], od);
            const bool mirrored = a & (4 >> k);
            t0[k] = mirrored ? thi : tlo;
            t1[k] = mirrored ? tlo : thi;
        }
        const M in = p[q].valid & (vmax(max3(t0[0], t0[1], t0[2]), ray.tnear) <= vmin(min3(t1[0], t1[1], t1[2]), ray.tfar));
        lanes[q] = in;
        if (none(in)) continue;
        const F big(inf);
        const int first = std::countr_zero(mask_bits(in)) & (K - 1);  // `in` has a lane
        bool own_walk = false;
        for (int k = 0; k < 3; ++k) {
            const F o = ray.org[k], r = ray.rdir[k];
            // Every packet's rays leave one point, not only the group's
            // first: packets_meeting_box culls by one origin per packet.
            org[k][q] = lane(o, first);
            own_walk = own_walk || (mask_bits(o != F(org[k][q])) & mask_bits(in)) != 0;
            r_lo[k][q] = lane_min<K>(select(in, r, big));
            r_hi[k][q] = lane_max<K>(select(in, r, -big));
            // Rays nearly parallel to a plane of the axes: reciprocals of
            // one sign spread far apart (kMaxReciprocalSpread).
            const float r_near = std::min(std::fabs(r_lo[k][q]), std::fabs(r_hi[k][q]));
            own_walk = own_walk || std::max(std::fabs(r_lo[k][q]), std::fabs(r_hi[k][q])) > kMaxReciprocalSpread * r_near;
        }
        if (own_walk) {  // out of the group: entering nothing, walking alone
            alone |= 1u << q;
            lanes[q] = in & !in;
            for (int k = 0; k < 3; ++k) org[k][q] = r_lo[k][q] = r_hi[k][q] = 0.0f;
            continue;
        }
        live |= 1u << q;
        for (int k = 0; k < 3; ++k) {
            t0_lo[k][q] = lane_min<K>(select(in, t0[k], big));
            t0_hi[k][q] = lane_max<K>(select(in, t0[k], -big));
            t1_lo[k][q] = lane_min<K>(select(in, t1[k], big));
            t1_hi[k][q] = lane_max<K>(select(in, t1[k], -big));
        }
        near_lo[q] = lane_min<K>(select(in, ray.tnear, big));
        far_hi[q] = lane_max<K>(select(in, ray.tfar, -big));
        for (int k = 0; k < 3; ++k) {
            const F o = ray.org[k], r = ray.rdir[k];
            non_finite = non_finite + select(in, (o - o) + (r - r), F(0.0f));
            g_lo[k] = std::min(g_lo[k], org[k][q]);
            g_hi[k] = std::max(g_hi[k], org[k][q]);
        }
    }
    if (live == 0) return alone;
    struct UnsetMailbox : PacketMailbox {
        UnsetMailbox() : PacketMailbox(Unset{}) {}
    };
    UnsetMailbox mailbox[G];
    for (int q = 0; q < count; ++q) mailbox[q].clear();
    // Axis-parallel rays (an infinite reciprocal) bound nothing: no culling.
    const bool cull = !any(non_finite != non_finite);
    const PF tnear = PF::load_aligned(near_lo);
    PF tfar = PF::load_aligned(far_hi);
    // The packets of `packets` test the leaf with all their lanes still
    // traced (robust slabs): a lane's hit there is its own ray's, none closer
    // than its single ray's (that point lies in a leaf its own walk visits,
    // which holds the primitive too), and each packet's mailbox settles a
    // primitive for all its lanes at once, so one that spans several leaves
    // is tested once per packet. Clipping the lanes to the leaf's widened box
    // first, with no mailbox: 0.82-0.94x (before the leaves culled their
    // primitives by their boxes, the clip cut balls' tests 7-fold). Plain
    // slabs keep the clip, as a precaution: they can lose the leaf of a
    // single ray's closest hit (the k-d tree's packets found closer hits
    // than their single rays there without it). The group's bound on the
    // lanes' tfar shrinks with their hits.
    const float clip_margin = 2.0f * tree.margin;
    const float clip_below = (tree.cube.hi[0] - tree.cube.lo[0]) * kClipBelow;
    // A leaf: `n_refs` references from `leaf_refs` with their boxes.
    const auto test_leaf = [&](const std::uint32_t* leaf_refs, const Box3f* leaf_boxes, std::uint32_t n_refs,
                               const Box3f& box, std::uint32_t packets) {
        // Where enough packets reach the leaf, its primitives' boxes first
        // (as the k-d tree's groups): each packet then tests only those its
        // rays may meet.
        std::uint32_t may_hit[kMaxCulledRefs];
        const bool culled = cull && n_refs <= kMaxCulledRefs && std::popcount(packets) >= kMinPacketsToCull;
        if (culled) {
            const float pad = culling_box_pad(box, g_lo, g_hi);
            vfloat<8> tf[G / 8];  // packets_meeting_box takes the packets eight at a time
            for (int h = 0; h < G / 8; ++h) tf[h] = vfloat<8>::load_aligned(far_hi + 8 * h);
            for (std::uint32_t k = 0; k < n_refs; ++k)
                may_hit[k] = packets_meeting_box<G>(org, r_lo, r_hi, up, leaf_boxes[k], pad, tf);
        }
        for (; packets != 0; packets &= packets - 1) {
            const int q = std::countr_zero(packets);
            RayPacket<K>& ray = p[q].ray;
            M in = lanes[q];
            if constexpr (Slabs == SlabMethod::Plain) {
                F t0, t1;
                in = ray_box_interval<F>(in, ray.org, ray.rdir, ray.tnear, ray.tfar, box, clip_margin, t0, t1);
                if (none(in)) continue;
            }
            if (culled)
                test_refs<K, AnyHit, true>(isect, leaf_refs, n_refs, in, ray, p[q].hit, p[q].occluded, may_hit, 1u << q,
                                           &mailbox[q]);
            else
                test_refs<K, AnyHit>(isect, leaf_refs, n_refs, in, ray, p[q].hit, p[q].occluded, nullptr, 0, &mailbox[q]);
            if constexpr (AnyHit) {
                lanes[q] = lanes[q] & !p[q].occluded;
                if (none(lanes[q])) live &= ~(1u << q), far_hi[q] = -inf;
            } else {
                far_hi[q] = lane_max<K>(select(lanes[q], p[q].ray.tfar, F(-inf)));
            }
        }
        tfar = PF::load_aligned(far_hi);
    };
    // A leaf of the tree, or an inner node that is a leaf to groups.
    const auto test_node = [&](std::uint32_t index, const Box3f& box, std::uint32_t packets) {
        const OctreeNode node = nodes[index];
        if (node.is_leaf()) {
            test_leaf(refs + node.first, tree.ref_boxes.data() + node.first, node.count, box, packets);
            return true;
        }
        if (!node.group_leaf()) return false;
        const OctreeNode whole = tree.group_leaves[index];
        test_leaf(tree.group_refs.data() + whole.first, tree.group_ref_boxes.data() + whole.first, whole.count, box,
                  packets);
        return true;
    };
    if (test_node(0, tree.cube, live)) return alone;
    GroupFrame<G> stack[kOctreeMaxDepth + 1];
    int sp = 0;
    GroupFrame<G>* f = &stack[0];
    for (int k = 0; k < 3; ++k) f->corner[k] = tree.cube.lo[k];
    f->half = 0.5f * (tree.cube.hi[0] - tree.cube.lo[0]);  // a cube (octree_cube)
    for (int k = 0; k < 3; ++k)
        f->set_axis(k, PF::load_aligned(t0_lo[k]), PF::load_aligned(t1_lo[k]), PF::load_aligned(t0_hi[k]),
                    PF::load_aligned(t1_hi[k]));
    f->packets = live;
    f->children = nodes[0].first;
    f->left = mirrored_children(nodes[0].occupied(), unsigned(a));
    for (;;) {
        if (f->left == 0) {
            if (sp == 0) return alone;
            f = &stack[--sp];
            continue;
        }
        const int c = std::countr_zero(f->left);
        f->left &= f->left - 1;
        const std::uint32_t entering = f->packets & live;
        if (entering == 0) continue;
        const std::uint32_t index = f->children + (unsigned(c) ^ unsigned(a));
        const std::uint8_t* half = kHalfIndex[c];
        const PF* lo_enter = &f->lo_enter[0][0];
        const PF* hi_leave = &f->hi_leave[0][0];
        const PF enter = max3(lo_enter[half[0]], lo_enter[half[1]], lo_enter[half[2]]);
        const PF leave = min3(hi_leave[half[0]], hi_leave[half[1]], hi_leave[half[2]]);
        const std::uint32_t packets = entering & mask_bits(vmax(enter, tnear) <= vmin(leave, tfar));
        if (packets == 0) continue;
        const unsigned real = unsigned(c) ^ unsigned(a);
        if (test_node(index, f->child_box(real), packets)) {
            if constexpr (AnyHit)
                if (live == 0) return alone;
            continue;
        }
        const OctreeNode node = nodes[index];
        // Small nodes clip the packets to their box too (see kClipBelow).
        const Box3f box = f->child_box(real);
        std::uint32_t clipped = packets;
        if (f->half <= clip_below) {
            for (std::uint32_t b = packets; b != 0; b &= b - 1) {
                const int q = std::countr_zero(b);
                F t0, t1;
                if (none(ray_box_interval<F>(lanes[q], p[q].ray.org, p[q].ray.rdir, p[q].ray.tnear, p[q].ray.tfar, box,
                                            clip_margin, t0, t1)))
                    clipped &= ~(1u << q);
            }
            if (clipped == 0) continue;
        }
        GroupFrame<G>* g = &stack[++sp];
        for (int k = 0; k < 3; ++k) g->corner[k] = box.lo[k];
        g->half = 0.5f * f->half;
        const PF* lo_leave = &f->lo_leave[0][0];
        const PF* hi_enter = &f->hi_enter[0][0];
        for (int k = 0; k < 3; ++k)
            g->set_axis(k, lo_enter[half[k]], lo_leave[half[k]], hi_enter[half[k]], hi_leave[half[k]]);
        g->packets = clipped;
        g->children = node.first;
        g->left = mirrored_children(node.occupied(), unsigned(a));
        f = g;
    }
}
#endif  // __AVX2__

}  // namespace

template <int K, bool AnyHit>
void octree_trace_packets(const Octree& tree, const Scene& scene, KernelChoice kernels,
                          const TriangleEdgeRecord* triangle_edges, std::span<const Rayf> rays,
                          std::span<Hitf> hits, bool groups) {
    using F = vfloat<K>;
    if (tree.empty() && tree.outside.empty()) {
        for (auto& h : hits) h = Hitf{};
        return;
    }
    const PacketRecordIntersector<F> isect{&scene, kernels, triangle_edges};
    // The slab form is chosen once for all packets, rdir once per packet.
    with_slab_form(kernels.slabs, [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
        // The primitives outside the leaves first: their hits shorten the walk.
        const auto walk_one = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
            if (!tree.empty()) trace_packet<K, AnyHit, Slabs>(tree, isect, ray, hit, valid, occluded);
        };
        const auto trace_one = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
            intersect_outside<K, AnyHit>(tree.outside, isect, ray, hit, valid, occluded);
            walk_one(ray, hit, valid, occluded);
        };
#if defined(__AVX2__)
        constexpr int G = octree_group_packets(K);
        static_assert(G % 8 == 0 && kWidthCompiled<G>, "trace_group: one lane of a vfloat<G> per packet");
        // Packets from one point and of one direction octant walk in groups
        // (trace_group); packets of spread origins (shadow rays from a tile's
        // surface points) ran 1.2-2.3x faster alone on tetra, teapot and
        // gears. The tie rule needs float tests (the double ones go lane by lane).
        if (groups && kernels.precision == Precision::Float) {
            trace_in_groups<K, G, AnyHit>(
                rays, hits, kernels.rcp,
                [](const LoadedPacket<K>& p) { return packet_octant<K>(p) >= 0 && one_origin<K>(p); }, trace_one,
                [&](LoadedPacket<K>* p, int count) {
                    if (count == 1) return trace_one(p[0].ray, p[0].hit, p[0].valid, p[0].occluded);
                    for (int q = 0; q < count; ++q)
                        intersect_outside<K, AnyHit>(tree.outside, isect, p[q].ray, p[q].hit, p[q].valid,
                                                     p[q].occluded);
                    if (tree.empty()) return;
                    for (std::uint32_t alone = trace_group<K, G, AnyHit, Slabs>(tree, isect, p, count); alone != 0;
                         alone &= alone - 1) {
                        LoadedPacket<K>& one = p[std::countr_zero(alone)];
                        walk_one(one.ray, one.hit, one.valid, one.occluded);
                    }
                });
            return;
        }
#else
        (void)groups;
#endif
        trace_in_packets<K, AnyHit>(rays, hits, kernels.rcp, trace_one);
    });
}

#if defined(__SSE4_2__)
template void octree_trace_packets<4, false>(const Octree&, const Scene&, KernelChoice,
                                             const TriangleEdgeRecord*, std::span<const Rayf>, std::span<Hitf>, bool);
template void octree_trace_packets<4, true>(const Octree&, const Scene&, KernelChoice,
                                            const TriangleEdgeRecord*, std::span<const Rayf>, std::span<Hitf>, bool);
#endif
#if defined(__AVX2__)
template void octree_trace_packets<8, false>(const Octree&, const Scene&, KernelChoice,
                                             const TriangleEdgeRecord*, std::span<const Rayf>, std::span<Hitf>, bool);
template void octree_trace_packets<8, true>(const Octree&, const Scene&, KernelChoice,
                                            const TriangleEdgeRecord*, std::span<const Rayf>, std::span<Hitf>, bool);
#endif
#if defined(__AVX512BW__)
template void octree_trace_packets<16, false>(const Octree&, const Scene&, KernelChoice,
                                              const TriangleEdgeRecord*, std::span<const Rayf>, std::span<Hitf>, bool);
template void octree_trace_packets<16, true>(const Octree&, const Scene&, KernelChoice,
                                             const TriangleEdgeRecord*, std::span<const Rayf>, std::span<Hitf>, bool);
#endif

}  // namespace raypack
