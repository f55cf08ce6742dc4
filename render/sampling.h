#pragma once
// Sampling helpers shared by the renderer and the measuring harness: random
// numbers, warps from the unit square, and an orthonormal frame.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <type_traits>
#include <utility>

#include "kernels/vec3.h"
#include "render/sin_cos_turns.h"

namespace raypack {

/// SplitMix64 (Steele, Lea, Flood, OOPSLA 2014): a counter-based generator,
/// so each pixel's numbers depend on (seed, pixel) alone.
inline std::uint64_t splitmix64(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/// A float uniform in [0, 1) from the top 24 bits of the next SplitMix64 draw.
inline float uniform01(std::uint64_t& state) { return float(splitmix64(state) >> 40) * 0x1.0p-24f; }

/// A double uniform in [lo, hi) from the top 53 bits of a 64-bit generator's draw.
template <class Generator>
double uniform(Generator& g, double lo = 0, double hi = 1) {
    return lo + (hi - lo) * double(g() >> 11) * 0x1.0p-53;
}

/// Uniform on the unit sphere (Marsaglia 1972 in its cylinder form).
template <class Generator>
Vec3d uniform_sphere(Generator& g) {
    const double z = uniform(g, -1, 1), phi = uniform(g, 0, 2 * std::numbers::pi);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/// sin and cos of the azimuth 2 pi u: in float through sin_cos_turns, which
/// the renderer's SIMD lanes compute bit for bit alike; in double through libm.
template <class T>
std::pair<T, T> sin_cos_of_turns(T u) {
    if constexpr (std::is_same_v<T, float>) {
        float s, c;
        sin_cos_turns(u, s, c);
        return {s, c};
    } else {
        const T phi = T(2) * std::numbers::pi_v<T> * u;
        return {std::sin(phi), std::cos(phi)};
    }
}

/// A point of the unit square mapped uniformly onto the unit disk by the polar
/// map (r = sqrt(u1), phi = 2 pi u2); z is 0.
template <class T>
Vec3<T> uniform_disk_polar(T u1, T u2) {
    const T r = std::sqrt(u1);
    const auto [sin_phi, cos_phi] = sin_cos_of_turns(u2);
    return {r * cos_phi, r * sin_phi, T(0)};
}

/// Malley's method: uniform on the unit disk, lifted to the hemisphere about
/// +z; the density is cos(theta) / pi (Pharr, Jakob, Humphreys, pbrt 4th ed.,
/// section A.5.3).
template <class T>
Vec3<T> cosine_hemisphere(T u1, T u2) {
    const Vec3<T> d = uniform_disk_polar(u1, u2);
    return {d.x, d.y, std::sqrt(std::max(T(0), T(1) - d.x * d.x - d.y * d.y))};
}

/// Shirley and Chiu's concentric map of the unit square onto the unit disk
/// ("A Low Distortion Map Between Disk and Square", JGT 1997): strata of
/// the square stay compact on the disk, unlike the polar map's slivers.
template <class T>
Vec3<T> concentric_disk(T u1, T u2) {
    const T a = T(2) * u1 - T(1), b = T(2) * u2 - T(1);
    if (a == 0 && b == 0) return {T(0), T(0), T(0)};
    const T quarter_pi = std::numbers::pi_v<T> / T(4);
    T r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = quarter_pi * (b / a);
    } else {
        r = b;
        phi = T(2) * quarter_pi - quarter_pi * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi), T(0)};
}

/// A direction about +z with density (n + 1) / (2 pi) cos^n(theta): the
/// Phong lobe of exponent n (Lafortune and Willems 1994: cos theta =
/// u1^(1 / (n + 1))). n = 0 is the uniform hemisphere.
template <class T>
Vec3<T> phong_lobe(T n, T u1, T u2) {
    const T cos_t = std::pow(u1, T(1) / (n + T(1)));
    const T sin_t = std::sqrt(std::max(T(0), T(1) - cos_t * cos_t));
    const auto [sin_phi, cos_phi] = sin_cos_of_turns(u2);
    return {sin_t * cos_phi, sin_t * sin_phi, cos_t};
}

/// Density of phong_lobe(n, ...) at a direction whose cosine to +z is cos_t.
template <class T>
T phong_lobe_pdf(T n, T cos_t) {
    return cos_t <= 0 ? T(0) : (n + T(1)) / (T(2) * std::numbers::pi_v<T>) * std::pow(cos_t, n);
}

/// An orthonormal frame (t, b, n) about unit n (Duff et al., "Building an
/// Orthonormal Basis, Revisited", JCGT 2017).
template <class T>
struct OrthonormalBasis {
    Vec3<T> t, b, n;

    explicit OrthonormalBasis(const Vec3<T>& unit_n) : n(unit_n) {
        const T sign = std::copysign(T(1), n.z);
        const T a = T(-1) / (sign + n.z), c = n.x * n.y * a;
        t = Vec3<T>(T(1) + sign * n.x * n.x * a, sign * c, -sign * n.x);
        b = Vec3<T>(c, sign + n.y * n.y * a, -n.y);
    }

    /// A direction given in the frame's coordinates, in world coordinates.
    Vec3<T> to_world(const Vec3<T>& local) const { return t * local.x + b * local.y + n * local.z; }
    /// A world direction in the frame's coordinates.
    Vec3<T> to_local(const Vec3<T>& world) const { return {dot(world, t), dot(world, b), dot(world, n)}; }
};

}  // namespace raypack
