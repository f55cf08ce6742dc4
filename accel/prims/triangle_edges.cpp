#include "accel/prims/triangle_edges.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace raypack {

TriangleEdgeTable::TriangleEdgeTable(const Scene& scene) : records_(scene.triangles.size()) {
    const TriangleSoA& tr = scene.triangles;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, records_.size(), 64 * 1024),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i < range.end(); ++i)
                              records_[i] = triangle_edge_record(tr, i);
                      });
}

}  // namespace raypack
