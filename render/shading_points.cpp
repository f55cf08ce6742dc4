#include "render/shading_points.h"

#include <algorithm>

namespace raypack {

void ShadingPoints::grow() {
    const std::size_t size = std::max<std::size_t>(2 * ray_.size(), 256 + kSpare);
    ray_.resize(size);
    for (auto* column : {view_, ns_, ng_, above_, color_})
        for (int a = 0; a < 3; ++a) column[a].resize(size);
    for (auto* column : {&kd_, &ks_, &shine_, &cutoff_}) column->resize(size);
}

void ShadingPoints::add(std::int32_t ray, const Vec3f& view, const Vec3f& ns, const Vec3f& ng, const Vec3f& above,
                        const Material& m, float specular_cutoff) {
    if (count_ + kSpare >= ray_.size()) grow();
    const std::size_t j = count_++;
    ray_[j] = ray;
    for (int a = 0; a < 3; ++a) {
        view_[a][j] = view[a];
        ns_[a][j] = ns[a];
        ng_[a][j] = ng[a];
        above_[a][j] = above[a];
        color_[a][j] = m.color[a];
    }
    kd_[j] = m.kd;
    ks_[j] = m.ks;
    shine_[j] = m.shine;
    cutoff_[j] = specular_cutoff;
}

ShadingPoints::Block ShadingPoints::next_block() {
    if (count_ + kSpare >= ray_.size()) grow();
    const std::size_t j = count_;
    Block b{&ray_[j], {}, {}, {}, {}, {}, &kd_[j], &ks_[j], &shine_[j], &cutoff_[j]};
    for (int a = 0; a < 3; ++a) {
        b.view[a] = &view_[a][j];
        b.ns[a] = &ns_[a][j];
        b.ng[a] = &ng_[a][j];
        b.above[a] = &above_[a][j];
        b.color[a] = &color_[a][j];
    }
    return b;
}

}  // namespace raypack
