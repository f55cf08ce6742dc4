#pragma once
// A packet's memory of the primitives it tested and on which lanes, for
// walks that meet a primitive again in a later leaf (the k-d tree's): the
// lanes' own mailboxes in one (Amanatides & Woo 1987 keep one per ray).
#include <algorithm>
#include <cstdint>
#include <iterator>

#include "kernels/ray.h"
#include "kernels/simd.h"

namespace raypack {

/// The primitives a packet tested lately and the lanes on which testing
/// them again could change nothing: a primitive met again in a later leaf
/// is tested only if some active lane is not among them. Which lanes those
/// are is the walk's to say: the lanes a primitive missed, or every lane
/// tested where ties go to the lowest primitive whatever the order (k-d
/// tree); a lane it hit may otherwise take it back on a tie at one t, as a
/// single ray testing it again would. Direct-mapped: a collision forgets,
/// which costs a test, never a hit.
class PacketMailbox {
public:
    PacketMailbox() { clear(); }
    /// Left unset until clear(): a group holds one per packet and clears only
    /// those it uses.
    struct Unset {};
    explicit PacketMailbox(Unset) {}

    void clear() { std::fill(std::begin(prim_), std::end(prim_), kNoPrim); }

    /// Lane bits of the lanes settled for `prim`; the caller adds to them.
    RAYPACK_INLINE std::uint32_t& settled(std::uint32_t prim) {
        const std::uint32_t slot = prim % kSlots;
        if (prim_[slot] != prim) prim_[slot] = prim, settled_[slot] = 0;
        return settled_[slot];
    }

private:
    static constexpr std::uint32_t kSlots = 32;
    std::uint32_t prim_[kSlots], settled_[kSlots];
};

}  // namespace raypack
