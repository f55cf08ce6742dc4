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

void ShadingPoints::add_many(std::size_t n, const std::int32_t* ray, const float* const view[3],
                             const float* const ns[3], const float* const ng[3], const float* const above[3],
                             const Material* const* m, const float* specular_cutoff) {
    if (count_ + kSpare >= ray_.size()) grow();
    const std::size_t j = count_;
    count_ += n;
    std::copy(ray, ray + n, &ray_[j]);
    for (int a = 0; a < 3; ++a) {
        std::copy(view[a], view[a] + n, &view_[a][j]);
        std::copy(ns[a], ns[a] + n, &ns_[a][j]);
        std::copy(ng[a], ng[a] + n, &ng_[a][j]);
        std::copy(above[a], above[a] + n, &above_[a][j]);
    }
    for (std::size_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) color_[a][j + i] = m[i]->color[a];
        kd_[j + i] = m[i]->kd;
        ks_[j + i] = m[i]->ks;
        shine_[j + i] = m[i]->shine;
        cutoff_[j + i] = specular_cutoff[i];
    }
}

}  // namespace raypack
