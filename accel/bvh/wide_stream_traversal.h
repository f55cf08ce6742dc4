#pragma once
// Streams of rays through the wide BVH (Barringer & Akenine-Moeller,
// "Dynamic Ray Stream Traversal", ACM TOG 33(4), 2014), included only by the
// .cpp files that instantiate the packet traversal.
//
// All the rays of a query walk the tree together as lists: a node is tested
// against its whole list K rays at a time (K rays x 1 box, the packet
// traversal's child_hits), and each child gets the list of the rays that
// meet it, compacted with AVX-512's compress. The lists carry their rays'
// data (origin, direction, reciprocals, tnear and the entry distance into
// the list's node), so that a node gathers only the rays' current closest
// hits, which drop the rays that have found one nearer than the node.
// Children are visited nearest first by the mean entry distance of their
// rays; a leaf tests each primitive against
// its list K rays at a time with the packet traversal's kernels (packet_leaf),
// reading each ray's current closest hit and writing back the ones it
// improves; a list shorter than `single_below` finishes its subtree one ray
// at a time (trace_wide_subtree), as a packet's lanes left alone do. So every
// (ray, primitive) pair tested gives the packet's and the single ray's bits;
// as there, only which of two nearly coincident hits is kept may differ.
//
// Incoherent rays (reflections from curved surfaces, shadow rays from points
// all over the scene) fall apart into lanes alone within a few levels of the
// packet walk; in a stream of thousands, each node still sees many of them.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "accel/bvh/wide_packet.h"
#include "accel/bvh/wide_packet_traversal.h"
#include "accel/packet_widths.h"

namespace raypack::wide_stream_detail {

using wide_packet_detail::PacketKernels;
using wide_packet_detail::PacketNodeRay;
using wide_packet_detail::PacketState;

/// The fields a list carries per ray, each an array of the list's capacity.
/// kEntry: the ray's entry distance into the list's node.
enum StreamField { kId, kOx, kOy, kOz, kDx, kDy, kDz, kRx, kRy, kRz, kTnear, kEntry, kStreamFields };

/// A node (or leaf) and the list of rays that meet it: `count` rays in a
/// region of the arena of kStreamFields arrays of `cap` floats.
struct StreamFrame {
    std::uint32_t node;
    std::uint32_t count, cap;
    std::size_t at;
};

/// Memory for the lists, used as a stack, kept between queries of a thread.
struct StreamArena {
    AlignedVector<float> data;
    std::vector<std::uint32_t> masks;
    AlignedVector<float> entries;  ///< per chunk and child, the lanes' entry distances
    std::vector<StreamFrame> frames;
    std::size_t top = 0;
    /// The query's rays by id: current tfar, and the closest hit so far
    /// (any hit: prim 0 once occluded).
    std::vector<float> tfar, t, u, v;
    std::vector<std::uint32_t> prim;

    /// A region for `count` rays; its capacity leaves room for a full
    /// compressed store past the last ray.
    template <int K>
    std::size_t alloc(std::uint32_t count, std::uint32_t& cap) {
        cap = (count + K - 1) / K * K + K;
        const std::size_t at = top;
        top += std::size_t(kStreamFields) * cap;
        if (top > data.size()) data.resize(std::max(top, 2 * data.size()));
        return at;
    }
};

inline StreamArena& thread_arena() {
    thread_local StreamArena arena;
    return arena;
}

#if defined(__AVX512F__)
/// The current per-ray state of a query (by ray id); any hit: t, u, v null.
struct StreamRays {
    float* tfar;
    float* t;
    float* u;
    float* v;
    std::uint32_t* prim;
};

template <int K>
RAYPACK_INLINE vint<K> load_ids(const float* f) {
    return vint<K>(_mm512_castps_si512(_mm512_load_ps(f)));
}

/// The node ray of lanes from a list's fields: set_packet_node_ray's far
/// reciprocals and signs from the stored reciprocals.
template <int K>
RAYPACK_INLINE void load_node_ray(const float* const* field, std::uint32_t i, SlabMethod slabs, PacketNodeRay<K>& n) {
    using F = vfloat<K>;
    const bool widen = slabs == SlabMethod::Robust;
    auto axis = [&](int o, int r, F& org, F& rd, F& rd_far, vmask<K>& negative) {
        org = F::load_aligned(field[o] + i);
        rd = F::load_aligned(field[r] + i);
        rd_far = wide_packet_detail::far_reciprocal<K>(rd, widen);
        negative = rd < F(0.0f);
    };
    axis(kOx, kRx, n.org.x, n.rdir.x, n.rdir_far.x, n.neg_x);
    axis(kOy, kRy, n.org.y, n.rdir.y, n.rdir_far.y, n.neg_y);
    axis(kOz, kRz, n.org.z, n.rdir.z, n.rdir_far.z, n.neg_z);
    n.tnear = F::load_aligned(field[kTnear] + i);
}

template <int N, int M, int K, TriangleMethod TM, bool AnyHit, class Kinds>
class StreamWalk {
public:
    using F = vfloat<K>;

    StreamWalk(const WideBvh<N, M>& bvh, const PacketKernels<K>& pk, int single_below, StreamRays rays,
               StreamArena& arena)
        : bvh_(bvh), pk_(pk), single_below_(std::max(single_below, 1)), rays_(rays), arena_(arena) {}

    /// Walks the list `root` (the root node's, made by the caller).
    void run(const StreamFrame& root) {
        arena_.frames.clear();
        arena_.frames.push_back(root);
        while (!arena_.frames.empty()) {
            const StreamFrame f = arena_.frames.back();
            arena_.frames.pop_back();
            // Regions above this one belong to frames already walked.
            arena_.top = f.at + std::size_t(kStreamFields) * f.cap;
            if (f.count < std::uint32_t(single_below_)) {
                alone(f);
            } else if (wide_child::is_leaf(f.node)) {
                leaf(f);
            } else {
                inner(f);
            }
        }
    }

private:
    const WideBvh<N, M>& bvh_;
    const PacketKernels<K>& pk_;
    int single_below_;
    StreamRays rays_;
    StreamArena& arena_;

    void fields(const StreamFrame& f, const float* out[kStreamFields]) const {
        for (int k = 0; k < kStreamFields; ++k) out[k] = arena_.data.data() + f.at + std::size_t(k) * f.cap;
    }

    static vmask<K> lanes_below(std::uint32_t n) {
        return mask_from_bits<K>(n >= std::uint32_t(K) ? (K == 32 ? ~0u : (1u << K) - 1u) : (1u << n) - 1u);
    }

    /// Each ray of the list finishes the subtree alone.
    void alone(const StreamFrame& f) const {
        const float* field[kStreamFields];
        fields(f, field);
        for (std::uint32_t j = 0; j < f.count; ++j) {
            const std::uint32_t id = std::bit_cast<std::uint32_t>(field[kId][j]);
            float& tfar = rays_.tfar[id];
            if (AnyHit && tfar == -std::numeric_limits<float>::infinity()) continue;
            Rayf r;
            r.org = {field[kOx][j], field[kOy][j], field[kOz][j]};
            r.dir = {field[kDx][j], field[kDy][j], field[kDz][j]};
            r.tnear = field[kTnear][j];
            r.tfar = tfar;
            Hitf h;  // any hit keeps no hit records (rays_.t, u, v are null)
            if constexpr (!AnyHit) h = Hitf{rays_.t[id], rays_.prim[id], rays_.u[id], rays_.v[id]};
            const NodeRay<N> nr = make_node_ray<NodeTest::Ordered, N>(r, pk_.kernels.slabs, pk_.kernels.rcp);
            const LeafRay<vfloat<M>> lr = make_leaf_ray<vfloat<M>>(r, TM);
            float t = tfar;
            const bool hit = trace_wide_subtree<N, M, TM, NodeTest::Ordered, AnyHit, false, NoTraversalCounts, Kinds>(
                bvh_, pk_.kernels.sphere, f.node, nr, lr, t, h);
            if (!hit) continue;
            if constexpr (AnyHit) {
                tfar = -std::numeric_limits<float>::infinity();
                rays_.prim[id] = 0;
            } else {
                tfar = t;
                rays_.t[id] = h.t;
                rays_.u[id] = h.u;
                rays_.v[id] = h.v;
                rays_.prim[id] = h.prim;
            }
        }
    }

    /// The leaf's primitives against the list, K rays at a time.
    void leaf(const StreamFrame& f) const {
        const float* field[kStreamFields];
        fields(f, field);
        const F minus_inf(-std::numeric_limits<float>::infinity());
        for (std::uint32_t i = 0; i < f.count; i += K) {
            const vmask<K> in = lanes_below(f.count - i);
            const vint<K> ids = load_ids<K>(field[kId] + i);
            RayPacket<K> p;
            p.org = {F::load_aligned(field[kOx] + i), F::load_aligned(field[kOy] + i), F::load_aligned(field[kOz] + i)};
            p.dir = {F::load_aligned(field[kDx] + i), F::load_aligned(field[kDy] + i), F::load_aligned(field[kDz] + i)};
            p.tnear = F::load_aligned(field[kTnear] + i);
            p.tfar = gather_floats<F>(rays_.tfar, ids, in);
            // Rays that have found a hit before the leaf since the list was
            // made (or, any hit, were stopped) take no part.
            const vmask<K> valid = in & (F::load_aligned(field[kEntry] + i) <= node_tfar(p.tfar));
            if (none(valid)) continue;
            LeafRay<F> lr;
            wide_packet_detail::set_packet_leaf_ray<K>(p, TM, lr);
            HitPacket<K> hit;
            hit.t = F(std::numeric_limits<float>::infinity());
            hit.u = hit.v = F(0.0f);
            for (auto& prim : hit.prim) prim = kNoPrim;
            vmask<K> occluded = valid & !valid;
            PacketState<K> s{hit, p.tfar, valid, occluded};
            wide_packet_detail::packet_leaf<TM, AnyHit, Kinds>(bvh_, pk_.kernels.sphere, f.node, lr, valid, s);
            const __m512i idx = __m512i(ids);
            if constexpr (AnyHit) {
                const __mmask16 m = __mmask16(mask_bits(occluded));
                if (m == 0) continue;
                _mm512_mask_i32scatter_ps(rays_.tfar, m, idx, __m512(minus_inf), 4);
                _mm512_mask_i32scatter_epi32(rays_.prim, m, idx, _mm512_setzero_si512(), 4);
            } else {
                const __m512i prims = _mm512_loadu_si512(hit.prim);
                const __mmask16 m = _mm512_cmpneq_epi32_mask(prims, _mm512_set1_epi32(int(kNoPrim)));
                if (m == 0) continue;
                _mm512_mask_i32scatter_ps(rays_.tfar, m, idx, __m512(s.tfar), 4);
                _mm512_mask_i32scatter_ps(rays_.t, m, idx, __m512(hit.t), 4);
                _mm512_mask_i32scatter_ps(rays_.u, m, idx, __m512(hit.u), 4);
                _mm512_mask_i32scatter_ps(rays_.v, m, idx, __m512(hit.v), 4);
                _mm512_mask_i32scatter_epi32(rays_.prim, m, idx, prims, 4);
            }
        }
    }

    /// The node's children against the list; each child met by some ray
    /// gets the list of those that meet it.
    void inner(const StreamFrame& f) {
        const WideNode<N>& node = bvh_.nodes[f.node];
        const std::uint32_t chunks = (f.count + K - 1) / K;
        if (arena_.masks.size() < std::size_t(chunks) * N) arena_.masks.resize(std::size_t(chunks) * N);
        if (arena_.entries.size() < std::size_t(chunks) * N * K) arena_.entries.resize(std::size_t(chunks) * N * K);
        std::uint32_t* masks = arena_.masks.data();
        float* entries = arena_.entries.data();
        std::uint32_t count[N] = {};
        F entry_sum[N];
        for (int c = 0; c < N; ++c) entry_sum[c] = F(0.0f);
        {
            const float* field[kStreamFields];
            fields(f, field);
            for (std::uint32_t k = 0, i = 0; k < chunks; ++k, i += K) {
                const vint<K> ids = load_ids<K>(field[kId] + i);
                const F tfar_nodes = node_tfar(gather_floats<F>(rays_.tfar, ids, lanes_below(f.count - i)));
                const vmask<K> in = lanes_below(f.count - i) & (F::load_aligned(field[kEntry] + i) <= tfar_nodes);
                if (none(in)) {
                    for (int c = 0; c < N; ++c) masks[std::size_t(k) * N + std::size_t(c)] = 0;
                    continue;
                }
                PacketNodeRay<K> nr;
                load_node_ray<K>(field, i, pk_.kernels.slabs, nr);
                for (int c = 0; c < N; ++c) {
                    F e;
                    const vmask<K> m = wide_packet_detail::child_hits<N, K>(node, c, nr, in, tfar_nodes, e);
                    const std::uint32_t bits = mask_bits(m);
                    masks[std::size_t(k) * N + std::size_t(c)] = bits;
                    e.store_aligned(entries + (std::size_t(k) * N + std::size_t(c)) * K);
                    count[c] += std::uint32_t(std::popcount(bits));
                    if constexpr (!AnyHit) entry_sum[c] = entry_sum[c] + select(m, e, F(0.0f));
                }
            }
        }
        // Push order: farthest first, so that the nearest is walked next.
        int order[N], n_hit = 0;
        float key[N];
        for (int c = 0; c < N; ++c) {
            if (count[c] == 0 || node.child[c] == wide_child::kEmpty) continue;
            if constexpr (!AnyHit) {
                alignas(64) float lanes[K];
                entry_sum[c].store_aligned(lanes);
                float sum = 0.0f;
                for (int l = 0; l < K; ++l) sum += lanes[l];
                key[c] = sum / float(count[c]);
            } else {
                key[c] = -float(count[c]);  // the most rays first
            }
            int at = n_hit++;
            for (; at > 0 && key[order[at - 1]] < key[c]; --at) order[at] = order[at - 1];
            order[at] = c;
        }
        if (n_hit == 0) return;
        std::size_t child_at[N];
        std::uint32_t child_cap[N], fill[N] = {};
        for (int o = 0; o < n_hit; ++o) {
            const int c = order[o];
            child_at[c] = arena_.alloc<K>(count[c], child_cap[c]);
        }
        // The arena may have moved: fields are read after the allocations.
        const float* field[kStreamFields];
        fields(f, field);
        float* base = arena_.data.data();
        for (std::uint32_t k = 0, i = 0; k < chunks; ++k, i += K) {
            __m512 v[kStreamFields];
            for (int q = 0; q < kStreamFields; ++q) v[q] = _mm512_load_ps(field[q] + i);
            for (int c = 0; c < N; ++c) {
                const std::uint32_t bits = masks[std::size_t(k) * N + std::size_t(c)];
                if (bits == 0) continue;
                float* out = base + child_at[c] + fill[c];
                v[kEntry] = _mm512_load_ps(entries + (std::size_t(k) * N + std::size_t(c)) * K);
                for (int q = 0; q < kStreamFields; ++q)
                    _mm512_storeu_ps(out + std::size_t(q) * child_cap[c], _mm512_maskz_compress_ps(__mmask16(bits), v[q]));
                fill[c] += std::uint32_t(std::popcount(bits));
            }
        }
        for (int o = 0; o < n_hit; ++o) {
            const int c = order[o];
            arena_.frames.push_back({node.child[c], count[c], child_cap[c], child_at[c]});
        }
    }
};

/// Closest hits (into `hits`) or occlusion (into `occluded`) of `rays` as
/// one stream of K = 16.
template <int N, int M, int K, TriangleMethod TM, bool AnyHit, class Kinds>
void trace_stream(const WideBvh<N, M>& bvh, const PacketKernels<K>& pk, int single_below, std::span<const Rayf> rays,
                  std::span<Hitf> hits, std::span<std::uint8_t> occluded) {
    static_assert(K == 16, "lists are compacted 16 lanes at a time");
    using F = vfloat<K>;
    const std::size_t n = rays.size();
    StreamArena& arena = thread_arena();
    std::vector<float>& tfar = arena.tfar;
    tfar.resize(n);
    arena.t.resize(AnyHit ? 0 : n);
    arena.u.resize(AnyHit ? 0 : n);
    arena.v.resize(AnyHit ? 0 : n);
    arena.prim.resize(n);
    arena.top = 0;
    std::uint32_t cap;
    const std::size_t at = arena.alloc<K>(std::uint32_t(n), cap);
    {
        float* base = arena.data.data() + at;
        PacketNodeRay<K> nr;
        LoadedPacket<K> p;
        alignas(64) std::uint32_t ids[K];
        for (int l = 0; l < K; ++l) ids[l] = std::uint32_t(l);
        F id = F(_mm512_castsi512_ps(_mm512_load_si512(ids)));  // ray numbers as float bits
        const F step(std::bit_cast<float>(std::uint32_t(K)));
        for (std::size_t first = 0; first < n; first += K) {
            load_fresh_packet<K>(rays, first, pk.kernels.rcp, p);
            wide_packet_detail::set_packet_node_ray<K>(p.ray, pk.kernels.slabs, nr);
            const F values[kStreamFields] = {id, nr.org.x, nr.org.y, nr.org.z, p.ray.dir.x, p.ray.dir.y, p.ray.dir.z,
                                             nr.rdir.x, nr.rdir.y, nr.rdir.z, nr.tnear,
                                             F(-std::numeric_limits<float>::infinity())};
            for (int q = 0; q < kStreamFields; ++q) values[q].store_aligned(base + std::size_t(q) * cap + first);
            id = F(_mm512_castsi512_ps(_mm512_add_epi32(_mm512_castps_si512(id), _mm512_castps_si512(step))));
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        tfar[i] = rays[i].tfar;
        arena.prim[i] = kNoPrim;
        if constexpr (!AnyHit) {
            arena.t[i] = std::numeric_limits<float>::infinity();
            arena.u[i] = arena.v[i] = 0.0f;
        }
    }
    const StreamRays state = AnyHit ? StreamRays{tfar.data(), nullptr, nullptr, nullptr, arena.prim.data()}
                                    : StreamRays{tfar.data(), arena.t.data(), arena.u.data(), arena.v.data(),
                                                 arena.prim.data()};
    StreamWalk<N, M, K, TM, AnyHit, Kinds> walk(bvh, pk, single_below, state, arena);
    walk.run({0, std::uint32_t(n), cap, at});
    for (std::size_t i = 0; i < n; ++i) {
        if constexpr (AnyHit) occluded[i] = arena.prim[i] == 0 ? 1 : 0;
        else hits[i] = Hitf{arena.t[i], arena.prim[i], arena.u[i], arena.v[i]};
    }
}
#endif

}  // namespace raypack::wide_stream_detail

namespace raypack {

template <int N, int M, bool AnyHit>
void wide_trace_stream(const WideBvh<N, M>& bvh, const Scene& scene, KernelChoice kernels,
                       const WidePacketConfig& config, std::span<const Rayf> rays, std::span<Hitf> hits,
                       std::span<std::uint8_t> occluded) {
#if defined(__AVX512BW__)
    constexpr int K = 16;
    if (bvh.nodes.empty() || kernels.precision == Precision::Double) {
        // No tree, or leaves tested by id: the packets' walk answers.
        if constexpr (AnyHit) {
            wide_occluded_packets<N, M, K>(bvh, scene, kernels, config, rays, occluded);
        } else {
            wide_trace_packets<N, M, K>(bvh, scene, kernels, config, rays, hits);
        }
        return;
    }
    const wide_packet_detail::PacketKernels<K> pk{kernels, {&scene, kernels}, {&scene, kernels}};
    // Streams of at most 65,536 rays: ray numbers fit the lists' 32-bit
    // fields and the lists' memory stays bounded (their gain has levelled
    // off by 4,096 rays).
    constexpr std::size_t kMaxStream = std::size_t(1) << 16;
    auto run = [&]<TriangleMethod TM, class Kinds = PrimKinds>() {
        for (std::size_t first = 0; first < rays.size(); first += kMaxStream) {
            const std::size_t n = std::min(kMaxStream, rays.size() - first);
            wide_stream_detail::trace_stream<N, M, K, TM, AnyHit, Kinds>(
                bvh, pk, config.stream_single_below, rays.subspan(first, n),
                AnyHit ? hits : hits.subspan(first, n), AnyHit ? occluded.subspan(first, n) : occluded);
        }
    };
    if (specialisation_for(scene, kernels) == KindSpecialisation::Triangles)
        return run.template operator()<TriangleMethod::Moeller, TriangleKinds>();
    switch (kernels.triangle) {
        case TriangleMethod::Moeller: return run.template operator()<TriangleMethod::Moeller>();
        case TriangleMethod::Watertight: return run.template operator()<TriangleMethod::Watertight>();
        case TriangleMethod::Plane: return run.template operator()<TriangleMethod::Plane>();
    }
#else
    (void)bvh, (void)scene, (void)kernels, (void)config, (void)rays, (void)hits, (void)occluded;
    throw std::logic_error("wide_trace_stream: streams need AVX-512");
#endif
}

}  // namespace raypack
