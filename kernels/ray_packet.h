#pragma once
// Rays and hits as structure of arrays over lanes: RayPacket<K> holds K rays,
// one per lane of vfloat<K>. K = 1 is a plain scalar ray.
#include <cstdint>
#include <limits>
#include <span>

#include "kernels/aabb.h"
#include "kernels/ray.h"
#include "kernels/ray_transpose.h"
#include "kernels/simd.h"

namespace raypack {

/// Rays in lanes of F. rdir is 1 / dir per component, precomputed once per
/// packet for the slab tests.
template <class F>
struct RayLanes {
    Vec3<F> org, dir, rdir;
    F tnear, tfar;
};

/// Closest hits in lanes of F: t = +inf and prim = kNoPrim where nothing was hit.
template <class F>
struct HitLanes {
    F t, u, v;
    std::uint32_t prim[lanes_of<F>];
};

template <int K> using RayPacket = RayLanes<vfloat<K>>;
template <int K> using HitPacket = HitLanes<vfloat<K>>;

/// Loads up to K rays (count <= K) into a packet; the lanes past `count`
/// repeat the last ray and come back inactive in `valid`. rdir gets the
/// single ray's bits: `--rcp exact` divides all lanes at once (a division is
/// correctly rounded at any width; K scalar divisions per axis were 5% of a
/// gears render), `--rcp approx` runs the scalar estimate lane by lane.
template <int K>
RayPacket<K> load_packet(std::span<const Rayf> rays, vmask<K>& valid, RcpMethod rcp = RcpMethod::Exact) {
    using F = vfloat<K>;
    const std::size_t n = rays.size();
#if defined(__AVX2__)
    if constexpr (K == 8 || K == 16) {
        // A full packet moves as 8 x 8 transposes (kernels/ray_transpose.h).
        if (n == std::size_t(K) && rcp == RcpMethod::Exact) {
            __m256 row[2][8];
            for (int h = 0; h < K / 8; ++h) transpose_rays8(rays.data() + 8 * h, row[h]);
            auto field = [&](int f) -> F {
                if constexpr (K == 8) return F(row[0][f]);
#if defined(__AVX512F__)
                else return F(_mm512_insertf32x8(_mm512_castps256_ps512(row[0][f]), row[1][f], 1));
#endif
            };
            RayPacket<K> p;
            p.org = {field(0), field(1), field(2)};
            p.dir = {field(3), field(4), field(5)};
            p.tnear = field(6);
            p.tfar = field(7);
            p.rdir = reciprocal(p.dir);
            valid = F(1.0f) > F(0.0f);
            return p;
        }
    }
#endif
    alignas(64) float f[8][K];
    alignas(64) float active[K];
    for (int i = 0; i < K; ++i) {
        const Rayf& r = rays[std::min<std::size_t>(std::size_t(i), n - 1)];
        const float vals[8] = {r.org.x, r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z, r.tnear, r.tfar};
        for (int c = 0; c < 8; ++c) f[c][i] = vals[c];
        active[i] = std::size_t(i) < n ? 1.0f : 0.0f;
    }
    RayPacket<K> p;
    p.org = {load_lanes<F>(f[0]), load_lanes<F>(f[1]), load_lanes<F>(f[2])};
    p.dir = {load_lanes<F>(f[3]), load_lanes<F>(f[4]), load_lanes<F>(f[5])};
    p.tnear = load_lanes<F>(f[6]);
    p.tfar = load_lanes<F>(f[7]);
    if (rcp == RcpMethod::Exact) {
        p.rdir = reciprocal(p.dir);
    } else {
        alignas(64) float rd[3][K];
        for (int i = 0; i < K; ++i) {
            const Vec3f r = reciprocal(Vec3f{f[3][i], f[4][i], f[5][i]}, rcp);
            rd[0][i] = r.x;
            rd[1][i] = r.y;
            rd[2][i] = r.z;
        }
        p.rdir = {load_lanes<F>(rd[0]), load_lanes<F>(rd[1]), load_lanes<F>(rd[2])};
    }
    valid = load_lanes<F>(active) > F(0.0f);
    return p;
}

}  // namespace raypack
