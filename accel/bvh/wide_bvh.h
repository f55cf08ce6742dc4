#pragma once
// An N-wide BVH (N = 4 or 8) whose child boxes are stored as SoA, so that one
// ray tests all N children with one SIMD slab test (Dammertz, Hanika, Keller,
// "Shallow Bounding Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent
// Rays", EGSR 2008; Ernst & Greiner, "Multi Bounding Volume Hierarchies",
// RT 2008; Wald, Benthin, Boulos, "Getting Rid of Packets", RT 2008). Leaves
// are runs of SoA blocks of M primitives of one kind (accel/prims/prim_kinds.h).
#include <cstdint>
#include <new>
#include <tuple>
#include <utility>
#include <vector>


#include "accel/prims/prim_kinds.h"
#include "kernels/aabb.h"

namespace raypack {

/// A child slot: an inner node index, or a leaf (top bit set) naming a run of
/// leaf blocks. Leaf bits: 30..28 kind (a PrimKind, or kMixed), 27..26
/// blocks - 1, 25..0 first block (for kMixed: the index into WideBvh::mixed).
namespace wide_child {
inline constexpr std::uint32_t kLeafBit = 0x80000000u;
inline constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;  ///< unused slot (its box is empty)
inline constexpr int kKindShift = 28, kCountShift = 26;
inline constexpr std::uint32_t kIndexMask = (1u << kCountShift) - 1u;
/// More blocks of one kind (a leaf of more than 4 M primitives, which only
/// unsplittable subtrees make) go through a mixed leaf.
inline constexpr std::uint32_t kMaxBlocks = 4;

RAYPACK_INLINE bool is_leaf(std::uint32_t c) { return (c & kLeafBit) != 0; }
/// The kind of a leaf holding several kinds, or more blocks than a slot names.
inline constexpr std::uint32_t kMixed = kPrimKinds;
static_assert(kMixed <= 7, "the kind field has three bits");
RAYPACK_INLINE std::uint32_t kind(std::uint32_t c) { return (c >> kKindShift) & 7u; }
RAYPACK_INLINE std::uint32_t blocks(std::uint32_t c) { return ((c >> kCountShift) & 3u) + 1u; }
RAYPACK_INLINE std::uint32_t first(std::uint32_t c) { return c & kIndexMask; }
inline std::uint32_t make_leaf(std::uint32_t k, std::uint32_t first_block, std::uint32_t block_count) {
    return kLeafBit | (std::uint32_t(k) << kKindShift) | ((block_count - 1u) << kCountShift) | first_block;
}
}  // namespace wide_child

/// N child boxes as SoA, rows lo_x, lo_y, lo_z, hi_x, hi_y, hi_z, then the N
/// child slots. An unused slot has the empty box lo = +inf, hi = -inf, which
/// the ordered slab test never enters. Rows are addressed by number so that a
/// ray picks its near and far planes per axis once (row a or a + 3).
template <int N>
struct alignas(64) WideNode {
    float bounds[6][N];
    std::uint32_t child[N];

    Box3f box(int i) const {
        return {{bounds[0][i], bounds[1][i], bounds[2][i]}, {bounds[3][i], bounds[4][i], bounds[5][i]}};
    }
    void set_box(int i, const Box3f& b) {
        for (int a = 0; a < 3; ++a) {
            bounds[a][i] = b.lo[a];
            bounds[a + 3][i] = b.hi[a];
        }
    }
};  // total: N = 4: 112 bytes, padded to 128 (two cache lines); N = 8: 224, padded to 256
static_assert(sizeof(WideNode<4>) == 128 && sizeof(WideNode<8>) == 256);

/// A leaf holding several kinds, or more blocks than a child slot can name:
/// a run of blocks per kind (indexed by PrimKind; count 0 if none).
struct MixedLeaf {
    std::uint32_t first[kPrimKinds];
    std::uint32_t count[kPrimKinds];
};  // total: 8 bytes a kind

/// Cache-line aligned storage through the aligned global `operator new`
/// (which raypack's command line replaces to ask for huge pages for large
/// blocks, app/heap_pages.cpp).
template <class T>
struct CacheLineAllocator {
    using value_type = T;
    CacheLineAllocator() = default;
    template <class U>
    CacheLineAllocator(const CacheLineAllocator<U>&) {}
    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(64))); }
    void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t(64)); }
    /// Default-initialises: resize() leaves trivial elements to their writer
    /// (the collapse writes every field), so no page is touched twice.
    template <class U>
    void construct(U* p) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
    template <class U>
    bool operator==(const CacheLineAllocator<U>&) const { return true; }
};

template <class T>
using AlignedVector = std::vector<T, CacheLineAllocator<T>>;

template <int N, int M>
struct WideBvh {
    AlignedVector<WideNode<N>> nodes;  ///< root at 0; empty for an empty scene
    PrimKinds::BlockStore<AlignedVector, M> block_store;  ///< one array per kind: blocks<Kind>()
    std::vector<MixedLeaf> mixed;
    TriangleLayout triangle_layout = TriangleLayout::Edges;
    int depth = 0;
    std::size_t leaves = 0;

    template <class Kind>
    AlignedVector<typename Kind::template Block<M>>& blocks() {
        return std::get<AlignedVector<typename Kind::template Block<M>>>(block_store);
    }
    template <class Kind>
    const AlignedVector<typename Kind::template Block<M>>& blocks() const {
        return std::get<AlignedVector<typename Kind::template Block<M>>>(block_store);
    }

    /// fn.template operator()<Kind>(blocks, count) for each run of blocks of
    /// leaf `code`, in PrimKinds order; fn returns whether it hit something,
    /// and with StopAtHit (any hit) the first hit ends the leaf. Whether any
    /// run hit. The one place a traversal learns a leaf's kinds.
    /// Kinds: the kinds the caller was compiled for (KindSpecialisation);
    /// the tree must hold no other.
    template <bool StopAtHit, class Kinds = PrimKinds, class Fn>
    RAYPACK_INLINE bool for_each_run(std::uint32_t code, Fn&& fn) const {
        const std::uint32_t first = wide_child::first(code), kind = wide_child::kind(code);
        if (kind != wide_child::kMixed) {
            const std::uint32_t count = wide_child::blocks(code);
            if constexpr (Kinds::size == 1) {
                using Kind = std::tuple_element_t<0, typename Kinds::Tuple>;
                return fn.template operator()<Kind>(blocks<Kind>().data() + first, count);
            } else {
                return Kinds::dispatch(PrimKind(kind), [&]<class Kind>() RAYPACK_INLINE_LAMBDA {
                    return fn.template operator()<Kind>(blocks<Kind>().data() + first, count);
                });
            }
        }
        const MixedLeaf& m = mixed[first];
        bool found = false;
        Kinds::until([&]<class Kind>() RAYPACK_INLINE_LAMBDA {
            constexpr int k = int(Kind::kind);
            const bool hit = fn.template operator()<Kind>(blocks<Kind>().data() + m.first[k], m.count[k]);
            found |= hit;
            return StopAtHit && hit;
        });
        return found;
    }

    std::size_t bytes() const {
        std::size_t b = nodes.size() * sizeof(WideNode<N>) + mixed.size() * sizeof(MixedLeaf);
        std::apply([&](const auto&... v) { ((b += v.size() * sizeof(v[0])), ...); }, block_store);
        return b;
    }
};

}  // namespace raypack
