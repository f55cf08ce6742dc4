#pragma once
// Instances as a leaf primitive kind (the material's "transformed objects"):
// a ray meets an instance by going to object space with the instance's
// inverse transform and through the structure built once for its object;
// t means the same point in both spaces, so hits need no transform back.
// Unlike the other kinds, a hit is named by the object's structure (the hit
// id inside the object, offset by Instance::first_hit_id), not by the
// block's `prim`: kinds with kNamesHits return those ids.
//
// The object's structure is reached through a virtual call on the Accel
// interface, out of line (accel/prims/instance_prims.cpp): that call is the
// seam that stops the traversal templates from recursing into themselves,
// and it costs little beside a whole traversal of the object.
#include <bit>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "accel/kernel_choice.h"
#include "accel/prims/leaf_common.h"
#include "kernels/aabb.h"
#include "kernels/ray_packet.h"
#include "scene/scene.h"

namespace raypack {

class Accel;

/// The structures of a scene's objects (Scene::objects), built once with the
/// structure over the scene and shared by every placement.
struct ObjectAccels {
    std::vector<std::unique_ptr<Accel>> accels;
    ObjectAccels();
    ~ObjectAccels();
};

template <int M>
struct InstanceBlock {
    float lo[3][M], hi[3][M];     ///< the placements' world bounds (NaN past the count)
    const Instance* instance[M];  ///< into the scene's instances; nullptr past the count
    const Accel* object[M];       ///< the object's structure
    std::uint32_t prim[M];
};

/// One ray (world space) through an instance: a closest hit closer than
/// hit.t / ray.tfar is recorded with its id (first_hit_id + the object's id).
bool intersect_instance(const Instance& instance, const Accel& object, const Rayf& ray, Hitf& hit);
/// Up to 16 rays (world space, rays[i] for lane i of `active`) through an
/// instance as one packet of the object's structure: the bits of the lanes
/// hit, with hits[lane] set for those.
std::uint32_t intersect_instance_packet(const Instance& instance, const Accel& object, int width,
                                        std::uint32_t active, Rayf* rays, Hitf* hits);

struct InstancePrims {
    static constexpr PrimKind kind = PrimKind::Instance;
    static constexpr bool kNamesHits = true;
    template <int M>
    using Block = InstanceBlock<M>;

    template <int M>
    static void pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene,
                     const BlockLayout& layout);

    /// One ray against the instances of a block: the placements whose
    /// boxes it meets, nearest box first (as a node test would order them),
    /// each with the closest hit so far as its tfar.
    template <TriangleMethod, class F, int M>
    static mask_of<F> intersect_block(const Block<M>& b, SphereMethod, const LeafRay<F>& r, const F& tfar, F& t, F& u,
                                      F& v, std::uint32_t* ids) {
        F entry;
        std::uint32_t boxes = mask_bits(box_lanes<F>(mask_of<F>(true), r, tfar, load_vec<F>(b.lo), load_vec<F>(b.hi), entry));
        for (int j = 0; j < M; ++j)  // the padding's NaN boxes do not fail every slab test
            if (b.prim[j] == kNoPrim) boxes &= ~(1u << j);
        alignas(64) float entries[M], ts[M], us[M], vs[M], hit[M];
        entry.store_aligned(entries);
        Rayf ray{{lane(r.org.x, 0), lane(r.org.y, 0), lane(r.org.z, 0)},
                 {lane(r.dir.x, 0), lane(r.dir.y, 0), lane(r.dir.z, 0)}, lane(r.tnear, 0), lane(tfar, 0)};
        for (int j = 0; j < M; ++j) ts[j] = us[j] = vs[j] = hit[j] = 0.0f, ids[j] = kNoPrim;
        while (boxes != 0) {
            int j = std::countr_zero(boxes);
            for (std::uint32_t rest = boxes & (boxes - 1); rest != 0; rest &= rest - 1)
                if (entries[std::countr_zero(rest)] < entries[j]) j = std::countr_zero(rest);
            boxes &= ~(1u << j);
            if (entries[j] > ray.tfar) break;  // every other box starts farther still
            Hitf h;
            if (!intersect_instance(*b.instance[j], *b.object[j], ray, h)) continue;
            ray.tfar = h.t;
            ts[j] = h.t, us[j] = h.u, vs[j] = h.v, hit[j] = 1.0f, ids[j] = h.prim;
        }
        t = load_lanes<F>(ts), u = load_lanes<F>(us), v = load_lanes<F>(vs);
        return load_lanes<F>(hit) > F(0.0f);
    }

    /// The active lanes of a packet against instance j of a block: those
    /// whose span meets its box.
    template <TriangleMethod, class F, int M>
    static mask_of<F> intersect_slot(const Block<M>& b, int j, SphereMethod, const LeafRay<F>& r,
                                     const mask_of<F>& active, const F& tfar, F& t, F& u, F& v, std::uint32_t* ids) {
        F entry;
        const mask_of<F> in_box = box_lanes<F>(active, r, tfar, broadcast_row<F>(b.lo, j), broadcast_row<F>(b.hi, j), entry);
        if (none(in_box)) return in_box;
        return lanes<F>(*b.instance[j], *b.object[j], in_box, r.org, r.dir, r.tnear, tfar, t, u, v, ids);
    }

    template <class T>
    static bool intersect(const Scene& scene, std::uint32_t index, const KernelChoice& k, const Ray<T>& ray, T& t,
                          T& u, T& v, std::uint32_t& id);

    template <class F>
    static mask_of<F> intersect(const Scene& scene, std::uint32_t index, const KernelChoice& k, mask_of<F> valid,
                                const RayLanes<F>& ray, F& t, F& u, F& v, std::uint32_t* ids) {
        const Instance& inst = scene.instances[index];
        return lanes<F>(inst, object_accel(k, inst), valid, ray.org, ray.dir, ray.tnear, ray.tfar, t, u, v, ids);
    }

    static const Accel& object_accel(const KernelChoice& k, const Instance& inst);

private:
    /// The robust slab test (kernels/aabb.h): placement boxes are padded,
    /// and this keeps every ray that meets the exact box.
    template <class F>
    static RAYPACK_INLINE mask_of<F> box_lanes(const mask_of<F>& valid, const LeafRay<F>& r, const F& tfar,
                                               const Vec3<F>& lo, const Vec3<F>& hi, F& entry) {
        const SlabRay<F> slab{r.org, reciprocal(r.dir), {}, r.tnear, tfar};
        return intersect_box<SlabMethod::Robust, F>(valid, slab, lo, hi, entry);
    }

    template <class F>
    static mask_of<F> lanes(const Instance& inst, const Accel& object, const mask_of<F>& active, const Vec3<F>& org,
                            const Vec3<F>& dir, const F& tnear, const F& tfar, F& t, F& u, F& v,
                            std::uint32_t* ids) {
        constexpr int K = lanes_of<F>;
        alignas(64) float ox[K], oy[K], oz[K], dx[K], dy[K], dz[K], tn[K], tf[K];
        store_lanes(ox, org.x), store_lanes(oy, org.y), store_lanes(oz, org.z);
        store_lanes(dx, dir.x), store_lanes(dy, dir.y), store_lanes(dz, dir.z);
        store_lanes(tn, tnear), store_lanes(tf, tfar);
        Rayf rays[K];
        Hitf hits[K];
        for (int l = 0; l < K; ++l) rays[l] = Rayf{{ox[l], oy[l], oz[l]}, {dx[l], dy[l], dz[l]}, tn[l], tf[l]};
        const std::uint32_t bits = intersect_instance_packet(inst, object, K, mask_bits(active), rays, hits);
        alignas(64) float ts[K], us[K], vs[K], hit[K];
        for (int l = 0; l < K; ++l) {
            const bool h = (bits >> l) & 1u;
            ts[l] = h ? hits[l].t : 0.0f, us[l] = hits[l].u, vs[l] = hits[l].v, hit[l] = h ? 1.0f : 0.0f;
            ids[l] = hits[l].prim;
        }
        t = load_lanes<F>(ts), u = load_lanes<F>(us), v = load_lanes<F>(vs);
        return load_lanes<F>(hit) > F(0.0f);
    }
};

/// Whether a primitive kind names its hits itself (InstancePrims) instead of
/// by the block's `prim`.
template <class Kind>
inline constexpr bool names_hits = requires { Kind::kNamesHits; };

}  // namespace raypack
