#pragma once
// The loop every packet traversal shares: cut the rays into packets of K
// (the last one ragged, its missing lanes inactive), trace each, and write
// the hits back in the exchange layout (for any hit, prim 0 = occluded).
#include <algorithm>
#include <bit>
#include <limits>
#include <span>
#include <utility>

#include "kernels/ray_packet.h"
#include "kernels/ray_transpose.h"

namespace raypack {

#if defined(__AVX2__)
/// A full packet's answers into K consecutive hits (kernels/ray_transpose.h);
/// for any hit, prim 0 where occluded.
template <int K, bool AnyHit>
RAYPACK_INLINE void store_packet_hits(const HitPacket<K>& hit, const vmask<K>& occluded, Hitf* out) {
    using F = vfloat<K>;
    F t = hit.t, u = hit.u, v = hit.v, prim;
    if constexpr (AnyHit) {
        // t = +inf, u = v = 0, prim 0 in the occluded lanes, kNoPrim elsewhere
        // (selected as float bit patterns).
        t = F(std::numeric_limits<float>::infinity());
        u = v = F(0.0f);
        prim = select(occluded, F(0.0f), F(std::bit_cast<float>(kNoPrim)));
    } else {
        prim = F::load_unaligned(reinterpret_cast<const float*>(hit.prim));
    }
    if constexpr (K == 8) store_hits8(t, prim, u, v, out);
#if defined(__AVX512F__)
    else store_hits16(t, prim, u, v, out);
#endif
}
#endif

/// `trace_packet(ray, hit, valid, occluded)` traces one packet: it records
/// closest hits in `hit`, or sets the `occluded` lanes for any-hit queries.
/// `rcp` computes the packets' reciprocal directions (`--rcp`).
template <int K, bool AnyHit, class TracePacket>
void trace_in_packets(std::span<const Rayf> rays, std::span<Hitf> hits, RcpMethod rcp, TracePacket&& trace_packet) {
    using F = vfloat<K>;
    for (std::size_t first = 0; first < rays.size(); first += K) {
        const std::size_t n = std::min<std::size_t>(K, rays.size() - first);
        vmask<K> valid;
        RayPacket<K> ray = load_packet<K>(rays.subspan(first, n), valid, rcp);
        HitPacket<K> hit;
        hit.t = F(std::numeric_limits<float>::infinity());
        hit.u = hit.v = F(0.0f);
        for (auto& p : hit.prim) p = kNoPrim;
        vmask<K> occluded = valid & !valid;
        trace_packet(ray, hit, valid, occluded);
#if defined(__AVX2__)
        if constexpr (K == 8 || K == 16) {
            if (n == std::size_t(K)) {
                store_packet_hits<K, AnyHit>(hit, occluded, hits.data() + first);
                continue;
            }
        }
#endif
        alignas(64) float t[K], u[K], v[K];
        store_lanes(t, hit.t);
        store_lanes(u, hit.u);
        store_lanes(v, hit.v);
        const std::uint32_t occ = mask_bits(occluded);
        for (std::size_t i = 0; i < n; ++i) {
            if constexpr (AnyHit) {
                hits[first + i] = Hitf{};
                if ((occ >> i) & 1u) hits[first + i].prim = 0;
            } else {
                hits[first + i] = Hitf{t[i], hit.prim[i], u[i], v[i]};
            }
        }
    }
}

}  // namespace raypack
