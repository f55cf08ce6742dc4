#include "accel/prims/instance_prims.h"

#include <cassert>
#include <limits>

#include "accel/accel.h"

namespace raypack {

ObjectAccels::ObjectAccels() = default;
ObjectAccels::~ObjectAccels() = default;

bool intersect_instance(const Instance& instance, const Accel& object, const Rayf& ray, Hitf& hit) {
    const Rayf r = ray_in_object(instance, ray);
    Hitf h;
    object.intersect({&r, 1}, {&h, 1});
    if (!h.found()) return false;
    hit = h;
    hit.prim = instance.first_hit_id + h.prim;
    return true;
}

std::uint32_t intersect_instance_packet(const Instance& instance, const Accel& object, int width,
                                        std::uint32_t active, Rayf* rays, Hitf* hits) {
    assert(width <= 16);
    for (int l = 0; l < width; ++l) {
        if ((active >> l) & 1u) {
            rays[l] = ray_in_object(instance, rays[l]);
        } else {
            // An empty span: no structure reports a hit for it.
            rays[l] = Rayf{{0, 0, 0}, {1, 0, 0}, 1.0f, 0.0f};
        }
        hits[l] = Hitf{};
    }
    object.intersect_packets(width, {rays, std::size_t(width)}, {hits, std::size_t(width)});
    std::uint32_t bits = 0;
    for (int l = 0; l < width; ++l) {
        if (!((active >> l) & 1u) || !hits[l].found()) continue;
        hits[l].prim += instance.first_hit_id;
        bits |= 1u << l;
    }
    return bits;
}

const Accel& InstancePrims::object_accel(const KernelChoice& k, const Instance& inst) {
    assert(k.objects != nullptr);
    return *k.objects->accels[inst.object];
}

template <class T>
bool InstancePrims::intersect(const Scene& scene, std::uint32_t index, const KernelChoice& k, const Ray<T>& ray, T& t,
                              T& u, T& v, std::uint32_t& id) {
    const Instance& inst = scene.instances[index];
    Rayf world;
    if constexpr (std::is_same_v<T, float>) {
        world = ray;
    } else {
        // --precision double: the object's structure takes float rays; its
        // own tests run in double on them.
        world = Rayf{Vec3f(ray.org), Vec3f(ray.dir), float(ray.tnear), float(ray.tfar)};
        if (double(world.tfar) > ray.tfar) world.tfar = std::nextafter(world.tfar, -INFINITY);
        if (double(world.tnear) < ray.tnear) world.tnear = std::nextafter(world.tnear, INFINITY);
    }
    Hitf h;
    if (!intersect_instance(inst, object_accel(k, inst), world, h)) return false;
    t = T(h.t), u = T(h.u), v = T(h.v), id = h.prim;
    return true;
}

template bool InstancePrims::intersect<float>(const Scene&, std::uint32_t, const KernelChoice&, const Ray<float>&,
                                              float&, float&, float&, std::uint32_t&);
template bool InstancePrims::intersect<double>(const Scene&, std::uint32_t, const KernelChoice&, const Ray<double>&,
                                               double&, double&, double&, std::uint32_t&);

template <int M>
void InstancePrims::pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene,
                         const BlockLayout& layout) {
    assert(prims.size() <= std::size_t(M));
    fill_rows(block.lo, kBlockPadding);
    fill_rows(block.hi, kBlockPadding);
    for (int j = 0; j < M; ++j) {
        block.instance[j] = nullptr;
        block.object[j] = nullptr;
        block.prim[j] = kNoPrim;
    }
    for (std::size_t j = 0; j < prims.size(); ++j) {
        const Instance& inst = scene.instances[scene.prims[prims[j]].index];
        set_row(block.lo, int(j), inst.bounds.lo);
        set_row(block.hi, int(j), inst.bounds.hi);
        block.instance[j] = &inst;
        block.object[j] = layout.objects->accels[inst.object].get();
        block.prim[j] = prims[j];
    }
}

template void InstancePrims::pack<4>(Block<4>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);
template void InstancePrims::pack<8>(Block<8>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);

}  // namespace raypack
