#pragma once
// Roots of a t^2 + 2 b t + c = 0 (note the half linear coefficient).
#include <cmath>
#include <utility>

namespace raypack {

/// Numerically stable roots (Press et al., Numerical Recipes 5.6): the root
/// that would suffer cancellation is taken from the product of the roots.
/// Returns false when there is no real root; otherwise t0 <= t1.
template <class T>
bool solve_quadratic_half(T a, T b, T c, T& t0, T& t1) {
    const T disc = b * b - a * c;
    if (!(disc >= T(0)) || a == T(0)) return false;
    const T root = std::sqrt(disc);
    const T q = b >= T(0) ? -(b + root) : -(b - root);
    if (q == T(0)) {  // b == 0 and c == 0: both roots at 0
        t0 = t1 = T(0);
        return true;
    }
    t0 = q / a;
    t1 = c / q;
    if (t0 > t1) std::swap(t0, t1);
    return true;
}

/// The nearer of two sorted roots inside [tnear, tfar], if any.
template <class T>
bool nearest_root_in(T t0, T t1, T tnear, T tfar, T& t) {
    if (t0 >= tnear && t0 <= tfar) { t = t0; return true; }
    if (t1 >= tnear && t1 <= tfar) { t = t1; return true; }
    return false;
}

}  // namespace raypack
