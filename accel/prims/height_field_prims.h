#pragma once
// Height fields as a leaf primitive kind: a block names up to M fields. One
// ray against a block walks each field in turn (the scalar walk); K rays
// against one field walk it in lockstep, one lane a ray
// (kernels/height_field_walk.h).
#include <cstdint>
#include <span>
#include <type_traits>

#include "accel/kernel_choice.h"
#include "accel/prims/leaf_common.h"
#include "kernels/height_field_walk.h"
#include "kernels/ray_packet.h"
#include "scene/scene.h"

namespace raypack {

template <int M>
struct HeightFieldBlock {
    const HeightField* field[M];  ///< into Scene::height_fields; nullptr past the count
    std::uint32_t prim[M];
};

struct HeightFieldPrims {
    static constexpr PrimKind kind = PrimKind::HeightField;
    template <int M>
    using Block = HeightFieldBlock<M>;

    template <int M>
    static void pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene, const BlockLayout&);

    /// One ray (broadcast in r) against the fields of a block.
    template <TriangleMethod, class F, int M>
    static mask_of<F> intersect_block(const Block<M>& b, SphereMethod, const LeafRay<F>& r, const F& tfar, F& t, F& u,
                                      F& v) {
        const Rayf ray{{lane(r.org.x, 0), lane(r.org.y, 0), lane(r.org.z, 0)},
                       {lane(r.dir.x, 0), lane(r.dir.y, 0), lane(r.dir.z, 0)}, lane(r.tnear, 0), lane(tfar, 0)};
        alignas(64) float ts[M], us[M], vs[M], hit[M];
        for (int j = 0; j < M; ++j) {
            ts[j] = us[j] = vs[j] = hit[j] = 0.0f;
            if (b.prim[j] != kNoPrim) hit[j] = intersect_height_field(*b.field[j], ray, ts[j], us[j], vs[j]) ? 1.0f : 0.0f;
        }
        t = load_lanes<F>(ts), u = load_lanes<F>(us), v = load_lanes<F>(vs);
        return load_lanes<F>(hit) > F(0.0f);
    }

    /// The active lanes of a packet against field j of a block.
    template <TriangleMethod, class F, int M>
    static mask_of<F> intersect_slot(const Block<M>& b, int j, SphereMethod, const LeafRay<F>& r,
                                     const mask_of<F>& active, const F& tfar, F& t, F& u, F& v) {
        return lanes(*b.field[j], active, r.org, r.dir, r.tnear, tfar, t, u, v);
    }

    template <class T>
    static bool intersect(const Scene& scene, std::uint32_t index, const KernelChoice&, const Ray<T>& ray, T& t, T& u,
                          T& v) {
        return intersect_height_field(scene.height_fields[index], ray, t, u, v);
    }

    template <class F>
    static mask_of<F> intersect(const Scene& scene, std::uint32_t index, const KernelChoice&, mask_of<F> valid,
                                const RayLanes<F>& ray, F& t, F& u, F& v) {
        return lanes(scene.height_fields[index], valid, ray.org, ray.dir, ray.tnear, ray.tfar, t, u, v);
    }

private:
    /// K rays against one field: the lockstep walk (kernels/height_field_walk.h),
    /// each lane the scalar walk's bits.
    template <class F>
    static mask_of<F> lanes(const HeightField& field, const mask_of<F>& active, const Vec3<F>& org,
                            const Vec3<F>& dir, const F& tnear, const F& tfar, F& t, F& u, F& v) {
        if constexpr (std::is_floating_point_v<F>) {
            if (!active) return false;
            return intersect_height_field(field, Rayf{org, dir, tnear, tfar}, t, u, v);
        } else {
            return intersect_height_field_lanes<F>(field, active, org, dir, tnear, tfar, t, u, v);
        }
    }
};

}  // namespace raypack
