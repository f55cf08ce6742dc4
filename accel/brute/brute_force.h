#pragma once
// The oracle: tests every primitive for every ray. Slow by design and simple
// enough to trust; every other structure is checked against it.
#include "accel/accel.h"

namespace raypack {

class BruteForce final : public Accel {
public:
    BruteForce(const Scene& scene, KernelChoice kernels);
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    /// No nodes; prims = every primitive for a closest hit, up to the first hit for any hit.
    bool count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                         TraversalCounts& counts) const override;

    /// The same search in double precision, for reference answers.
    Hit<double> intersect_double(const Ray<double>& ray) const;

private:
    const Scene* scene_;
    KernelChoice kernels_;
};

}  // namespace raypack
