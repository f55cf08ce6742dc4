#pragma once
// Which variant of each test runs: `--sphere`, `--triangle`, `--slabs`,
// `--rcp` and `--precision`, chosen once per structure.
#include "kernels/aabb.h"
#include "kernels/sphere.h"
#include "kernels/triangle.h"

namespace raypack {

struct ObjectAccels;

/// Arithmetic of the primitive tests (`--precision`): float, or double on
/// the float ray and scene converted exactly (the closest hit is still kept
/// as a float t). Traversal stays float; with robust slabs it never culls a
/// box the exact ray meets, so double tests lose no hit to it.
enum class Precision { Float, Double };

/// Which variant of each test to run: primitive tests, slab tests of the
/// traversal (`--slabs`), reciprocal directions (`--rcp`) and precision.
struct KernelChoice {
    SphereMethod sphere = SphereMethod::Geometric;
    TriangleMethod triangle = TriangleMethod::Moeller;
    SlabMethod slabs = SlabMethod::Robust;
    RcpMethod rcp = RcpMethod::Exact;
    Precision precision = Precision::Float;
    /// `--specialise`: whether the wide BVHs may run loops compiled for the
    /// scene's primitive kinds alone (accel/prims/prim_kinds.h).
    bool specialise = true;
    /// Not a choice but where the instance test finds the structures of the
    /// scene's objects (accel/prims/instance_prims.h): set by build_accel for
    /// a scene with instances, carried with the kernels because every leaf
    /// test receives them.
    const ObjectAccels* objects = nullptr;
};

}  // namespace raypack
