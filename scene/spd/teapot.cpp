// SPD "teapot": Newell's teapot, each Bezier patch evaluated on a SIZE x SIZE
// grid and split into triangles with vertex normals, on a checkerboard of
// SIZE x SIZE squares; two lights (Haines 1987, "A Proposal for Standard
// Graphics Environments").
#include <array>
#include <cmath>

#include "scene/spd/generators.h"
#include "scene/spd/nff_writer.h"
#include "scene/spd/teapot_data.h"

namespace raypack::spd {

namespace {

/// Bicubic Bezier basis: a point is (s^3 s^2 s 1) * M * G * M^T * (t^3 t^2 t 1)^T.
constexpr Mat4 kBezier = {{{-1.0, 3.0, -3.0, 1.0}, {3.0, -6.0, 3.0, 0.0}, {-3.0, 3.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}}};

Mat4 transpose(const Mat4& m) {
    Mat4 r{};
    for (std::size_t i = 0; i < 4; ++i)
        for (std::size_t j = 0; j < 4; ++j) r[j][i] = m[i][j];
    return r;
}

double dot4(const Vec4& a, const Vec4& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
}

/// M * G * M^T for the x, y and z control values of one patch.
using PatchBasis = std::array<Mat4, 3>;

PatchBasis patch_basis(const std::array<int, 16>& patch) {
    const Mat4 bezier_t = transpose(kBezier);
    PatchBasis out{};
    for (std::size_t axis = 0; axis < 3; ++axis) {
        Mat4 g{};
        for (std::size_t r = 0; r < 4; ++r)
            for (std::size_t c = 0; c < 4; ++c) {
                const Vec3& v = teapot_data::kVertices[static_cast<std::size_t>(patch[r * 4 + c])];
                g[r][c] = axis == 0 ? v.x : axis == 1 ? v.y : v.z;
            }
        out[axis] = multiply(multiply(kBezier, g), bezier_t);
    }
    return out;
}

/// Power vector (u^3, u^2, u, 1) and its derivative (3u^2, 2u, 1, 0), built
/// by repeated multiplication as SPD does.
void power_vectors(double u, Vec4& value, Vec4& derivative) {
    std::array<double, 4> p{};
    std::array<double, 4> d{};
    double pv = 1.0;
    double dv = 1.0;
    for (int k = 3; k >= 0; --k) {
        const auto i = static_cast<std::size_t>(k);
        p[i] = pv;
        pv *= u;
        if (k == 3) {
            d[i] = 0.0;
            dv = 1.0;
        } else {
            d[i] = dv * static_cast<double>(3 - k);
            dv *= u;
        }
    }
    value = {p[0], p[1], p[2], p[3]};
    derivative = {d[0], d[1], d[2], d[3]};
}

/// Surface point and unit normal (t tangent x s tangent) at (s, t).
void evaluate_patch(const PatchBasis& basis, double s, double t, Vec3& point, Vec3& normal) {
    Vec4 sp, dsp, tp, dtp;
    power_vectors(s, sp, dsp);
    power_vectors(t, tp, dtp);
    std::array<double, 3> pos{};
    std::array<double, 3> sdir{};
    std::array<double, 3> tdir{};
    for (std::size_t i = 0; i < 3; ++i) {
        pos[i] = dot4(transform_coord(sp, basis[i]), tp);
        sdir[i] = dot4(transform_coord(dsp, basis[i]), tp);
        tdir[i] = dot4(transform_coord(sp, basis[i]), dtp);
    }
    point = {pos[0], pos[1], pos[2]};
    normal = cross({tdir[0], tdir[1], tdir[2]}, {sdir[0], sdir[1], sdir[2]});
    normalize(normal);
}

/// The lid knob and the bottom centre are cusps whose normal evaluates to
/// zero. A triangle with two vertices on the axis is degenerate (false);
/// with one, that vertex gets the axis direction as its normal.
bool fix_cusp(const std::array<Vec3, 3>& verts, std::array<Vec3, 3>& norms) {
    int count = 0;
    std::size_t on_axis = 0;
    for (std::size_t i = 3; i-- > 0;) {
        if (std::fabs(verts[i].x) <= 0.0001 && std::fabs(verts[i].y) <= 0.0001) {
            ++count;
            on_axis = i;
        }
    }
    if (count > 1) return false;
    if (count == 1) norms[on_axis] = {0.0, 0.0, verts[on_axis].z > 1.5 ? 1.0 : -1.0};
    return true;
}

void output_teapot(NffWriter& out, int size) {
    out.surface({1.0, 0.5, 0.1}, 0.0, 0.75, 0.25, 0.25, 37.0, 0.0, 0.0);
    for (const auto& patch : teapot_data::kPatches) {
        const PatchBasis basis = patch_basis(patch);
        for (int ss = 0; ss < size; ++ss)
            for (int ts = 0; ts < size; ++ts)
                for (int tri = 0; tri < 2; ++tri) {
                    // Grid cell corners 0..3 = (s,t), (s,t+1), (s+1,t+1),
                    // (s+1,t); triangles 0-1-2 and 2-3-0.
                    std::array<Vec3, 3> verts{};
                    std::array<Vec3, 3> norms{};
                    for (int v = 0; v < 3; ++v) {
                        const int corner = (v + tri * 2) % 4;
                        const double s =
                            static_cast<double>(ss + (corner / 2 != 0 ? 1 : 0)) / static_cast<double>(size);
                        const double t =
                            static_cast<double>(ts + (corner % 3 != 0 ? 1 : 0)) / static_cast<double>(size);
                        evaluate_patch(basis, s, t, verts[static_cast<std::size_t>(v)],
                                       norms[static_cast<std::size_t>(v)]);
                    }
                    if (fix_cusp(verts, norms)) out.triangle_patch(verts, norms);
                }
    }
}

/// Square (ss, ts) of the SIZE x SIZE board covering [-4, 4]^2 at z = 0.
std::array<Vec3, 4> board_square(int ss, int ts, int size) {
    std::array<Vec3, 4> v{};
    for (int i = 0; i < 4; ++i) {
        const double x = 4.0 * (2.0 * static_cast<double>(ss + (i % 3 != 0 ? 1 : 0)) / static_cast<double>(size) - 1.0);
        const double y = 4.0 * (2.0 * static_cast<double>(ts + (i / 2 != 0 ? 1 : 0)) / static_cast<double>(size) - 1.0);
        v[static_cast<std::size_t>(i)] = {x, y, 0.0};
    }
    return v;
}

void output_checkerboard(NffWriter& out, int size) {
    // All white squares, then all grey ones.
    for (int parity = 1; parity >= 0; --parity) {
        const double shade = parity == 1 ? 1.0 : 0.5;
        out.surface({shade, shade, shade}, 0.0, 0.5, 0.5, 0.5, 30.0, 0.0, 0.0);
        for (int ss = 0; ss < size; ++ss)
            for (int ts = 0; ts < size; ++ts)
                if ((ss + ts) % 2 == parity) out.polygon(board_square(ss, ts, size));
    }
}

}  // namespace

std::string generate_teapot(int size) {
    NffWriter out;
    out.background({0.078, 0.361, 0.753});
    out.viewpoint({4.86, 7.2, 5.4}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 45.0, 1.0, 512, 512);
    out.light({-3.1, 9.8, 12.1});
    out.light({11.3, 5.1, 8.8});
    output_checkerboard(out, size);
    output_teapot(out, size);
    return out.take();
}

}  // namespace raypack::spd
