// SPD "mount": a fractal mountain by Carpenter's midpoint displacement on a
// square grid, with four glass spheres in front; one light (Haines 1987,
// "A Proposal for Standard Graphics Environments"). This is the ORIGINAL
// database: its hash repeats itself, but the published image uses it.
#include <array>
#include <cmath>
#include <vector>

#include "scene/spd/generators.h"
#include "scene/spd/nff_writer.h"

namespace raypack::spd {

namespace {

constexpr double kFractalDimension = 2.2;  // between 2 and 3; sets the z variance
constexpr long kMountainNumber = 21;       // another value gives another mountain
constexpr double kCornerX = -1.0;
constexpr double kCornerY = -1.0;
constexpr double kWidth = 2.0;

/// The 1987 seed hash of grid point (a, b) at size factor c. It was written
/// for c <= 7; above, where its last term would shift by a negative count,
/// that term shifts right by c - 7 instead (the same bits of a, moved the
/// other way), and c <= 15 keeps the others defined.
unsigned long original_hash(int a, int b, int c) {
    const auto ua = static_cast<unsigned long>(a);
    const auto ub = static_cast<unsigned long>(b);
    const unsigned long low = c <= 7 ? ua << (7 - c) : ua >> (c - 7);
    return ((ua << (23 - c)) + (ub << (15 - c)) + low) & 0xffffUL;
}

/// Gaussian deviate from a seed: Numerical Recipes' GASDEV (polar
/// Box-Muller) over SPD's portable linear congruential generator.
double gauss_rand(long seed) {
    constexpr long kM = 134456;
    constexpr long kA = 8121;
    constexpr long kC = 28411;
    long ix2 = seed;
    double v1 = 0.0;
    double r = 0.0;
    do {
        const long ix1 = (kC + ix2 * kA) % kM;
        ix2 = (kC + ix1 * kA) % kM;
        v1 = static_cast<double>(ix1) * 2.0 * 1.0 / static_cast<double>(kM) - 1.0;
        const double v2 = static_cast<double>(ix2) * 2.0 * 1.0 / static_cast<double>(kM) - 1.0;
        r = v1 * v1 + v2 * v2;
    } while (r >= 1.0);
    return v1 * std::sqrt(-2.0 * std::log(r) / r);
}

/// Four crystal spheres stacked as a pyramid around CENTER (radius in w).
void output_sphere_pyramid(NffWriter& out, const Vec4& center) {
    Vec3 axis{1.0, 1.0, 0.0};
    normalize(axis);
    const double angle = std::acos(-1.0 / 3.0);  // the tetrahedral angle

    const Vec3 top{0.0, 0.0, center.w * std::sqrt(3.0 / 2.0)};
    out.sphere({center.x + top.x, center.y + top.y, center.z + top.z, center.w});

    const Vec3 base = transform_vector(top, axis_rotate_matrix(axis, angle));
    for (int i = 0; i < 3; ++i) {
        const Vec3 p = transform_vector(base, rotate_matrix(Axis::Z, static_cast<double>(i) * 2.0 * kPi / 3.0));
        out.sphere({p.x + center.x, p.y + center.y, p.z + center.z, center.w});
    }
}

struct MountainGrid {
    int size_factor;
    double points;     // grid cells per side, as a double
    double roughness;  // displacement per unit of cell width
};

/// Heights at the corners of a grid square: lower left, lower right, upper
/// right, upper left.
struct Corners {
    double ll, lr, ur, ul;
};

double displacement(const MountainGrid& g, int x, int y) {
    const long seed = kMountainNumber + static_cast<long>(original_hash(x, y, g.size_factor));
    return gauss_rand(seed);
}

/// The square of WIDTH cells with lower-left grid point (x, y): one cell
/// goes to `cell(x, y, corners)`, a larger square to its four displaced
/// quarter squares.
template <class Cell>
void grow_mountain(const MountainGrid& g, int width, int x, int y, const Corners& z, Cell&& cell) {
    if (width == 1) {
        cell(x, y, z);
        return;
    }

    const int half = width >> 1;
    const double half_side = static_cast<double>(half) * kWidth / g.points;
    const double rise = half_side * g.roughness;

    const double lower = (z.ll + z.lr) / 2.0 + rise * displacement(g, x + half, y);
    const double right = (z.lr + z.ur) / 2.0 + rise * displacement(g, x + width, y + half);
    const double upper = (z.ur + z.ul) / 2.0 + rise * displacement(g, x + half, y + width);
    const double left = (z.ul + z.ll) / 2.0 + rise * displacement(g, x, y + half);
    const double middle = (z.ll + z.lr + z.ur + z.ul) / 4.0 + 1.4142136 * rise * displacement(g, x + half, y + half);

    grow_mountain(g, half, x, y, {z.ll, lower, middle, left}, cell);
    grow_mountain(g, half, x + half, y, {lower, z.lr, right, middle}, cell);
    grow_mountain(g, half, x + half, y + half, {middle, right, z.ur, upper}, cell);
    grow_mountain(g, half, x, y + half, {left, middle, upper, z.ul}, cell);
}

/// One cell of the mountain as SPD writes it: two triangles.
void mountain_cell(NffWriter& out, const MountainGrid& g, int x, int y, const Corners& z) {
    const double lx = kCornerX + static_cast<double>(x) * kWidth / g.points;
    const double rx = kCornerX + static_cast<double>(x + 1) * kWidth / g.points;
    const double ly = kCornerY + static_cast<double>(y) * kWidth / g.points;
    const double uy = kCornerY + static_cast<double>(y + 1) * kWidth / g.points;
    const std::array<Vec3, 4> quad = {Vec3{lx, ly, z.ll}, Vec3{rx, ly, z.lr}, Vec3{rx, uy, z.ur}, Vec3{lx, uy, z.ul}};
    out.polygon(std::array<Vec3, 3>{quad[0], quad[1], quad[2]});
    out.polygon(std::array<Vec3, 3>{quad[2], quad[3], quad[0]});
}

MountainGrid mountain_grid(int size) {
    // Per-level scale ratio 2^(1/(D-1)) gives fractal dimension D.
    const double ratio = 2.0 / std::exp(std::log(2.0) / (kFractalDimension - 1.0));
    return {size, static_cast<double>(1 << size), std::sqrt(ratio * ratio - 1.0)};
}

/// What mount and terrain share: sky, view, light, the crystal spheres, and
/// the mountain's material.
NffWriter mountain_setting() {
    NffWriter out;
    out.background({0.078, 0.361, 0.753});
    out.viewpoint({-1.6, 1.6, 1.7}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 45.0, 0.01, 512, 512);
    out.light({-100.0, -100.0, 100.0});

    // Clear crystal spheres.
    out.surface({1.0, 1.0, 1.0}, 0.0, 0.1, 0.1, 0.4, 6.7, 0.9, 1.5);
    output_sphere_pyramid(out, {-0.8, 0.8, 1.0, 0.17});

    // Grey mountain.
    out.surface({0.5, 0.45, 0.35}, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    return out;
}

}  // namespace

std::string generate_mount(int size) {
    NffWriter out = mountain_setting();
    const MountainGrid grid = mountain_grid(size);
    grow_mountain(grid, 1 << size, 0, 0, {0.0, 0.0, 0.0, 0.0},
                  [&](int x, int y, const Corners& z) { mountain_cell(out, grid, x, y, z); });
    return out.take();
}

std::string generate_terrain(int size) {
    NffWriter out = mountain_setting();
    const MountainGrid grid = mountain_grid(size);
    const int n = (1 << size) + 1;  // samples per side
    std::vector<double> heights(std::size_t(n) * std::size_t(n));
    grow_mountain(grid, 1 << size, 0, 0, {0.0, 0.0, 0.0, 0.0}, [&](int x, int y, const Corners& z) {
        heights[std::size_t(y) * n + x] = z.ll;
        heights[std::size_t(y) * n + x + 1] = z.lr;
        heights[std::size_t(y + 1) * n + x + 1] = z.ur;
        heights[std::size_t(y + 1) * n + x] = z.ul;
    });
    // Heights mapped by z0 = 0, z1 = 1: as written, the mountain's own.
    out.height_field(n, n, {kCornerX, kCornerY, 0.0}, {kCornerX + kWidth, kCornerY + kWidth, 1.0}, heights);
    return out.take();
}

}  // namespace raypack::spd
