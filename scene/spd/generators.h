#pragma once
// The individual SPD generators behind generate_spd() (scene/spd/spd.h).
// Each returns the NFF text of its scene at the given size factor; the size
// has already been range-checked by the caller.
#include <string>

namespace raypack::spd {

std::string generate_balls(int size);
std::string generate_tetra(int size);
/// tetra of the same depth, its self-similarity written as instances: an
/// object of depth min(size, 6) in triangles, and for every three further
/// levels an object of 64 placements of the one below (not SPD;
/// docs/instancing.md).
std::string generate_tetra_instanced(int size);
std::string generate_mount(int size);
std::string generate_rings(int size);
std::string generate_tree(int size);
std::string generate_gears(int size);
std::string generate_teapot(int size);
/// Not an SPD scene: the Cornell box (size 1 with its blocks, 2 with spheres).
std::string generate_cornell(int size);
/// Not an SPD scene: mount's mountain as one height field of (2^size + 1)^2
/// samples (raypack's `hf`), with mount's spheres, view and light.
std::string generate_terrain(int size);

}  // namespace raypack::spd
