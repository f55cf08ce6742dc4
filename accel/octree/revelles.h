#pragma once
// The pieces of the parametric octree traversal of Revelles, Urena & Lastra,
// "An Efficient Parametric Algorithm for Octree Traversal", WSCG 2000.
//
// Every axis is mirrored so that the ray runs towards +: an axis whose
// direction has its sign bit set (-0 included) swaps the roles of the box's
// lo and hi planes and sets its bit in the mask `a` (x = 4, y = 2, z = 1);
// child c of the mirrored walk is child c ^ a of the real node. A node is
// then described by the parameters t0 (entry) and t1 (exit) of its slabs
// alone; the children's come from the midpoint parameters tm = (t0 + t1) / 2
// without touching a coordinate. A direction component of (almost) zero is
// clamped by reciprocal() (kernels/aabb.h) to +-1e18, which makes t0 and t1
// huge of opposite signs and tm's sign tell which half the ray lies in: the
// paper's +-infinity rule for tm, without its special case.
#include <algorithm>

namespace raypack::revelles {

/// The paper's new_node state table: from child c (mirrored), the next child
/// when the ray leaves through the x, y or z plane; 8 = out of the parent.
/// Leaving through the lower half's far plane moves to the upper half; the
/// upper half's far plane is the parent's.
inline constexpr unsigned char kNext[8][3] = {
    {4, 2, 1}, {5, 3, 8}, {6, 8, 3}, {7, 8, 8}, {8, 6, 5}, {8, 7, 8}, {8, 8, 7}, {8, 8, 8},
};

/// new_node(): the exit plane is the one crossed first (ties go to the later
/// axis, as in the paper; either is right since the ray touches both children).
inline int new_node(int c, float tx1, float ty1, float tz1) {
    if (tx1 < ty1) {
        if (tx1 < tz1) return kNext[c][0];
    } else if (ty1 < tz1) {
        return kNext[c][1];
    }
    return kNext[c][2];
}

/// first_node(): the child the ray is in at parameter `te`. With te the
/// node's entry (the largest t0) this is the paper's table, which tests the
/// two axes other than the entry plane's against te (the entry axis's own
/// tm is never below its t0); with te = tnear > entry it is the child the
/// ray starts in.
inline int first_node(float txm, float tym, float tzm, float te) {
    return (txm < te ? 4 : 0) | (tym < te ? 2 : 0) | (tzm < te ? 1 : 0);
}

}  // namespace raypack::revelles
