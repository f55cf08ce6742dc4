#pragma once
// The 3D-DDA of dda.h for K rays at once, each lane stepping its own walk:
// the same start cell, the same crossing distances t_first + k * tDelta (one
// fused multiply-add) and the same choice of axis, so every lane visits
// exactly the cells its single-ray walk visits, in the same order.
//
// Per-axis counters are kept as floats (exact below 2^24 cells per axis,
// which the caller checks); the linear cell index is a vector of int32.
// S is the slab form of the cell planes' first crossings, as in dda.h.
#include <cstdint>
#include <limits>

#include "accel/cell_kernel_variants.h"
#include "accel/grid/grid.h"
#include "kernels/ray_packet.h"
#include "kernels/simd.h"

namespace raypack {

template <int K, SlabMethod S = SlabMethod::Robust>
class GridDdaPacket {
public:
    using F = vfloat<K>;
    using M = vmask<K>;
    using I = vint<K>;

    /// The next plane each lane crosses: the axis (one mask per axis) and
    /// the distance, which is also where the lane's current cell ends.
    struct Crossing {
        M x, y, z;
        F t;
    };

    /// Walks of the packet's rays from t_start (their slab-test entry distances).
    GridDdaPacket(const GridGeometry& g, const RayLanes<F>& ray, const F& t_start) {
        const F inf(std::numeric_limits<float>::infinity()), zero(0.0f), one(1.0f);
        std::int32_t stride = 1;
        cell_ = I(0);
        for (int a = 0; a < 3; ++a) {
            const F org = ray.org[a], dir = ray.dir[a], rdir = ray.rdir[a];
            const F lo(g.bounds.lo[a]), cs(g.cell_size[a]), last(float(g.res[a] - 1));
            // Cell of the start point, as dda.h computes it.
            const F p = org + dir * t_start;
            F f = (p - lo) * F(g.inv_cell_size[a]);
            f = select(f > zero, f, zero);
            f = select(f < last, f, last);
            const I i = truncate(f);
            const F fi = to_float(i);
            cell_ = cell_ + i * I(stride);
            const M parallel = (vabs(dir) < F(kMinRcpInput)) | (dir != dir);
            const M up = dir > zero;
            left_[a] = select(parallel, zero, select(up, last - fi, fi));
            const I s(stride);
            stride_[a] = select_int(up, s, -s) & ~int_mask(parallel);
            const F plane = lo + select(up, fi + one, fi) * cs;
            t_first_[a] = t_next_[a] = select(parallel, inf, plane_distance<S>(plane, org, rdir, org * rdir));
            t_delta_[a] = select(parallel, zero, cs * vabs(rdir));
            steps_[a] = zero;
            stride *= g.res[a];
        }
    }

    /// Linear cell index of every lane (meaningful for lanes still walking).
    void cells(std::int32_t* out) const { cell_.store_aligned(out); }

    /// Nearest plane crossing per lane, chosen exactly as GridDda::next() does.
    Crossing crossing() const {
        const F tx = t_next_[0], ty = t_next_[1], tz = t_next_[2];
        const M xy = tx < ty;
        const M x = xy & (tx < tz);
        const M y = (!xy) & (ty < tz);
        const M z = !(x | y);
        return {x, y, z, select(x, tx, select(y, ty, tz))};
    }

    /// Steps the lanes of `m` across `c`; returns the lanes of `m` that
    /// thereby leave the grid (they stay where they were).
    M advance(const Crossing& c, const M& m) {
        const F zero(0.0f), one(1.0f);
        const M out = m & ((c.x & (left_[0] == zero)) | (c.y & (left_[1] == zero)) | (c.z & (left_[2] == zero)));
        const M go = m & !out;
        const M axis[3] = {go & c.x, go & c.y, go & c.z};
        I cell_step(0);
        for (int a = 0; a < 3; ++a) {
            left_[a] = select(axis[a], left_[a] - one, left_[a]);
            steps_[a] = select(axis[a], steps_[a] + one, steps_[a]);
            // vfmadd is fused at every width (xsimd::fma on its plain avx2 arch is not).
            t_next_[a] = select(axis[a], vfmadd(steps_[a], t_delta_[a], t_first_[a]), t_next_[a]);
            cell_step = cell_step + (stride_[a] & int_mask(axis[a]));
        }
        cell_ = cell_ + cell_step;
        return out;
    }

private:
    // Conversions; at width 16 zero-masked with a full mask, the same
    // instructions without the undefined pass-through operand that makes
    // gcc 12 warn (as kernels/simd.h does for vmin).
    static I truncate(const F& f) {
#if defined(__AVX512F__)
        if constexpr (K == 16) return _mm512_maskz_cvttps_epi32(__mmask16(0xFFFF), f);
        else
#endif
            return xsimd::batch_cast<std::int32_t>(f);
    }
    static F to_float(const I& i) {
#if defined(__AVX512F__)
        if constexpr (K == 16) return _mm512_maskz_cvtepi32_ps(__mmask16(0xFFFF), i);
        else
#endif
            return xsimd::batch_cast<float>(i);
    }
    /// A float lane mask as int32 lanes of all ones or zeros.
    static I int_mask(const M& m) { return xsimd::bitwise_cast<I>(xsimd::bitwise_cast(m)); }
    static I select_int(const M& m, const I& a, const I& b) {
        const I k = int_mask(m);
        return (a & k) | (b & ~k);
    }

    F t_next_[3], t_first_[3], t_delta_[3], steps_[3];
    F left_[3];    ///< planes still to cross along each axis before leaving the grid
    I stride_[3];  ///< change of the linear cell index per step
    I cell_;
};

}  // namespace raypack
