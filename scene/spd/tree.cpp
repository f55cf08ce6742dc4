// SPD "tree": a binary tree of cones with spheres at the joints, grown by
// Aono & Kunii's method (IEEE CG&A, May 1984), over a square field; seven
// lights (Haines 1987, "A Proposal for Standard Graphics Environments").
#include <array>

#include "scene/spd/generators.h"
#include "scene/spd/nff_writer.h"

namespace raypack::spd {

namespace {

// Shape of the tree.
constexpr double kBranchAngle[2] = {40.0, 25.0};         // degrees from the parent axis
constexpr double kContraction[2] = {0.65, 0.70};         // child length / parent length
constexpr double kDivergence[2] = {90.0, 140.0 + 90.0};  // degrees about the parent axis
constexpr double kDiameterRatio = 0.67;                  // child width / parent width
constexpr double kWidthToHeight = 0.15;

/// Parent-to-child transform of each branch: scale, lift to the parent's
/// tip, then turn by the divergence and branching angles.
using BranchMatrices = std::array<Mat4, 2>;

BranchMatrices make_branch_matrices() {
    BranchMatrices out{};
    for (std::size_t i = 0; i < 2; ++i) {
        const Mat4 tilt = rotate_matrix(Axis::X, kBranchAngle[i] * kPi / 180.0);
        const Mat4 turn = rotate_matrix(Axis::Z, kDivergence[i] * kPi / 180.0);
        Mat4 scale_lift = identity_matrix();
        scale_lift[0][0] = kContraction[i];
        scale_lift[1][1] = kContraction[i];
        scale_lift[2][2] = kContraction[i];
        scale_lift[3][2] = 1.0;
        out[i] = multiply(multiply(tilt, turn), scale_lift);
    }
    return out;
}

/// One branch: the unit Z segment under CUR, then its two children.
void grow_tree(NffWriter& out, const BranchMatrices& branch, const Mat4& cur, double scale, int depth) {
    const Vec3 b = transform_point({0.0, 0.0, 0.0}, cur);
    const Vec4 base{b.x, b.y, b.z, scale * kWidthToHeight};
    const Vec3 a = transform_point({0.0, 0.0, 1.0}, cur);
    const Vec4 apex{a.x, a.y, a.z, base.w * kDiameterRatio};
    out.cone(base, apex);
    out.sphere(apex);
    if (depth <= 0) return;
    for (const Mat4& m : branch) grow_tree(out, branch, multiply(m, cur), scale * kDiameterRatio, depth - 1);
}

}  // namespace

std::string generate_tree(int size) {
    NffWriter out;
    out.background({0.078, 0.361, 0.753});
    out.viewpoint({4.5, 0.4, 2.0}, {0.0, 0.0, 1.5}, {0.0, 0.0, 1.0}, 45.0, 1.0, 512, 512);
    for (const Vec3& l :
         {Vec3{-5.0, 5.0, 50.0}, Vec3{30.0, -30.0, 30.0}, Vec3{-40.0, -30.0, 20.0}, Vec3{10.0, 30.0, 40.0},
          Vec3{-30.0, 40.0, 10.0}, Vec3{50.0, 25.0, 20.0}, Vec3{-10.0, -60.0, 30.0}})
        out.light(l);

    // Green field.
    out.surface({0.2, 0.7, 0.2}, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    const std::array<Vec3, 4> field = {Vec3{50.0, 50.0, 0.0}, Vec3{-50.0, 50.0, 0.0}, Vec3{-50.0, -50.0, 0.0},
                                       Vec3{50.0, -50.0, 0.0}};
    out.polygon(field);

    // Brown tree.
    out.surface({0.55, 0.4, 0.2}, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    grow_tree(out, make_branch_matrices(), identity_matrix(), 1.0, size);
    return out.take();
}

}  // namespace raypack::spd
