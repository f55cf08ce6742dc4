#pragma once
// The loop every packet traversal shares: cut the rays into packets of K
// (the last one ragged, its missing lanes inactive), trace each, and write
// the answers back: hits in the exchange layout (for any hit, prim 0 =
// occluded), or any-hit answers as bytes (1 = occluded).
#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
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

/// A packet's answers into hits[first, first + n) (n <= K), in the exchange
/// layout (for any hit, prim 0 where occluded).
template <int K, bool AnyHit>
RAYPACK_INLINE void store_packet(const HitPacket<K>& hit, const vmask<K>& occluded, std::span<Hitf> hits,
                                 std::size_t first, std::size_t n) {
#if defined(__AVX2__)
    if constexpr (K == 8 || K == 16) {
        if (n == std::size_t(K)) {
            store_packet_hits<K, AnyHit>(hit, occluded, hits.data() + first);
            return;
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

/// A packet's any-hit answers into occluded[first, first + n) (n <= K): 1
/// where occluded. Straight from the lane mask: the hits layout's 16 bytes
/// a ray, converted to a byte afterwards, was a tenth of a shadow-ray
/// query's time (`raypack trace`, gears, 1 thread).
template <int K, bool AnyHit>
RAYPACK_INLINE void store_packet(const HitPacket<K>&, const vmask<K>& occluded, std::span<std::uint8_t> out,
                                 std::size_t first, std::size_t n) {
    static_assert(AnyHit, "closest hits go into Hitf");
    const std::uint32_t bits = mask_bits(occluded) & (n >= 32 ? ~0u : (1u << n) - 1u);
#if defined(__BMI2__)
    // Each mask bit to the low bit of a byte, eight at a time.
    for (std::size_t i = 0; i < n; i += 8) {
        const std::uint64_t bytes = _pdep_u64(bits >> i, 0x0101010101010101ull);
        std::memcpy(out.data() + first + i, &bytes, std::min<std::size_t>(8, n - i));
    }
#else
    for (std::size_t i = 0; i < n; ++i) out[first + i] = std::uint8_t((bits >> i) & 1u);
#endif
}

/// Asks for the cache lines of elements [first, first + count) of `data`,
/// clipped to it, for reading or (Write) for writing.
template <bool Write, class T>
RAYPACK_INLINE void prefetch_elements(std::span<T> data, std::size_t first, std::size_t count) {
    if (first >= data.size()) return;
    const char* c = reinterpret_cast<const char*>(data.data() + first);
    const std::size_t bytes = std::min(count, data.size() - first) * sizeof(T);
    for (std::size_t off = 0; off < bytes; off += 64) __builtin_prefetch(c + off, Write ? 1 : 0, 3);
}

/// A packet of up to K rays from rays[first...], with no hit yet.
template <int K>
struct LoadedPacket {
    RayPacket<K> ray;
    HitPacket<K> hit;
    vmask<K> valid, occluded;
    std::size_t n;
};
template <int K>
RAYPACK_INLINE void load_fresh_packet(std::span<const Rayf> rays, std::size_t first, RcpMethod rcp,
                                      LoadedPacket<K>& p) {
    using F = vfloat<K>;
    p.n = std::min<std::size_t>(K, rays.size() - first);
    p.ray = load_packet<K>(rays.subspan(first, p.n), p.valid, rcp);
    p.hit.t = F(std::numeric_limits<float>::infinity());
    p.hit.u = p.hit.v = F(0.0f);
    for (auto& prim : p.hit.prim) prim = kNoPrim;
    p.occluded = p.valid & !p.valid;
}

/// Whether the valid lanes of a packet leave one point (pinhole camera rays,
/// rays from one light): groups of such packets bound their rays tightly.
template <int K>
RAYPACK_INLINE bool one_origin(const LoadedPacket<K>& p) {
    const std::uint32_t bits = mask_bits(p.valid);
    if (!bits) return false;
    const int first = std::countr_zero(bits);
    for (int a = 0; a < 3; ++a)
        if (mask_bits(p.ray.org[a] != vfloat<K>(lane(p.ray.org[a], first))) & bits) return false;
    return true;
}

/// `trace_packet(ray, hit, valid, occluded)` traces one packet: it records
/// closest hits in `hit`, or sets the `occluded` lanes for any-hit queries.
/// `rcp` computes the packets' reciprocal directions (`--rcp`).
template <int K, bool AnyHit, class Answer, class TracePacket>
void trace_in_packets(std::span<const Rayf> rays, std::span<Answer> hits, RcpMethod rcp, TracePacket&& trace_packet) {
    LoadedPacket<K> p;
    for (std::size_t first = 0; first < rays.size(); first += K) {
        prefetch_elements<false>(rays, first + 8 * K, K);  // as in trace_in_groups, a few packets ahead
        load_fresh_packet<K>(rays, first, rcp, p);
        trace_packet(p.ray, p.hit, p.valid, p.occluded);
        store_packet<K, AnyHit>(p.hit, p.occluded, hits, first, p.n);
    }
}

/// The same in groups of up to G consecutive packets (G * K rays):
/// `trace_group(packets, count)` traces `count` loaded packets together.
/// `group_size(packet)` says how many packets a group led by `packet` may
/// hold, at most G (a walk may want fewer packets of some rays: the grid's
/// groups of rays from several points); a packet for which it is 0 cannot
/// start a group (its rays are not coherent enough to share a walk):
/// it is traced alone with `trace_packet`, without waiting for the packets
/// after it.
template <int K, int G, bool AnyHit, class Answer, class GroupSize, class TracePacket, class TraceGroup>
void trace_in_sized_groups(std::span<const Rayf> rays, std::span<Answer> hits, RcpMethod rcp, GroupSize&& group_size,
                           TracePacket&& trace_packet, TraceGroup&& trace_group) {
    LoadedPacket<K> p[G];
    std::size_t group_first = 0;
    int count = 0, size = G;
    auto flush = [&] {
        trace_group(p, count);
        for (int g = 0; g < count; ++g)
            store_packet<K, AnyHit>(p[g].hit, p[g].occluded, hits, group_first + std::size_t(g) * K, p[g].n);
        count = 0;
    };
    for (std::size_t first = 0; first < rays.size(); first += K) {
        // A group loads its packets at once and then walks for long without
        // touching the stream, so the hardware prefetcher, which follows a
        // stream a few lines ahead of its misses, falls behind (on Zen 5 a
        // third of a group walk's time went into loading rays from a large
        // array). Each packet loaded asks for its place in the next group,
        // and for its own hits, which are stored after the walk.
        prefetch_elements<false>(rays, first + std::size_t(size) * K, K);
        prefetch_elements<true>(hits, first, K);
        LoadedPacket<K>& next = p[count];
        load_fresh_packet<K>(rays, first, rcp, next);
        if (count == 0) {
            size = std::min(G, group_size(next));
            if (size < 1) {
                size = G;
                trace_packet(next.ray, next.hit, next.valid, next.occluded);
                store_packet<K, AnyHit>(next.hit, next.occluded, hits, first, next.n);
                continue;
            }
            group_first = first;
        }
        if (++count == size) flush();
    }
    if (count != 0) flush();
}

/// trace_in_sized_groups with groups of G packets, where `may_lead(packet)`
/// says whether a packet may start one.
template <int K, int G, bool AnyHit, class Answer, class MayLead, class TracePacket, class TraceGroup>
void trace_in_groups(std::span<const Rayf> rays, std::span<Answer> hits, RcpMethod rcp, MayLead&& may_lead,
                     TracePacket&& trace_packet, TraceGroup&& trace_group) {
    trace_in_sized_groups<K, G, AnyHit>(
        rays, hits, rcp, [&](const LoadedPacket<K>& p) { return may_lead(p) ? G : 0; }, trace_packet, trace_group);
}

/// trace_in_groups for walks that may decline a group: `trace_group(packets,
/// count)` returns false, tracing nothing, when the group's packets cannot
/// share its walk (k-d tree: not from one point; octree: not one direction
/// octant), and each is then traced alone with `trace_packet`.
template <int K, int G, bool AnyHit, class Answer, class MayLead, class TracePacket, class TraceGroup>
void trace_in_groups_or_alone(std::span<const Rayf> rays, std::span<Answer> hits, RcpMethod rcp, MayLead&& may_lead,
                              TracePacket&& trace_packet, TraceGroup&& trace_group) {
    trace_in_groups<K, G, AnyHit>(rays, hits, rcp, may_lead, trace_packet, [&](LoadedPacket<K>* p, int count) {
        if (count > 1 && trace_group(p, count)) return;
        for (int q = 0; q < count; ++q) trace_packet(p[q].ray, p[q].hit, p[q].valid, p[q].occluded);
    });
}

}  // namespace raypack
