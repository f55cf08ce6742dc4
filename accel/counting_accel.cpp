#include "accel/counting_accel.h"

#include <stdexcept>
#include <vector>

namespace raypack {

CountingAccel::CountingAccel(const Accel& inner) : inner_(inner) {
    TraversalCounts none;
    if (!inner_.count_traversal({}, false, {}, none))
        throw std::invalid_argument(inner_.stats().name + " cannot count its traversal");
}

void CountingAccel::intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const {
    TraversalCounts c;
    inner_.count_traversal(rays, false, hits, c);
    add(c, rays.size());
}

void CountingAccel::occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const {
    std::vector<Hitf> hits(rays.size());
    TraversalCounts c;
    inner_.count_traversal(rays, true, hits, c);
    for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = hits[i].found() ? 1 : 0;
    add(c, rays.size());
}

void CountingAccel::add(const TraversalCounts& c, std::size_t rays) const {
    nodes_ += c.nodes;
    prims_ += c.prims;
    leaves_ += c.leaves;
    empty_leaves_ += c.empty_leaves;
    rays_ += rays;
}

TraversalCounts CountingAccel::totals() const {
    return {nodes_.load(), prims_.load(), leaves_.load(), empty_leaves_.load()};
}

}  // namespace raypack
