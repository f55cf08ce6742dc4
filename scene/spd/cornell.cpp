// The Cornell box as NFF with raypack's extensions (docs/scene-format.md).
// Geometry, camera and light position from the Cornell Program of Computer
// Graphics' published measurements of the physical box
// (https://www.graphics.cornell.edu/online/box/data.html, in millimetres);
// wall colours are the RGB reflectances commonly derived from its spectra
// (white 0.725 0.71 0.68, red 0.63 0.065 0.05, green 0.14 0.45 0.091), the
// light's colour the ratio of its measured RGB emission (18.4 : 15.6 : 8.0).
// The light is lowered 0.1 mm below the ceiling so that the two surfaces
// do not coincide. Size 2 replaces the blocks with raypack's own variant: a
// mirror sphere and a glass sphere of radius 82.5 resting on the floor.
#include <string>

#include "scene/spd/generators.h"

namespace raypack::spd {

namespace {

constexpr const char* kRoom = R"(# Cornell box (graphics.cornell.edu/online/box/data.html)
v
from 278 273 -800
at 278 273 0
up 0 1 0
angle 39.3077
hither 1
resolution 512 512
b 0 0 0
# white
f 0.725 0.71 0.68 1 0 0 0 1
la 343 548.7 227 0 0 105 -130 0 0 1 0.848 0.435
p 4
552.8 0 0
0 0 0
0 0 559.2
549.6 0 559.2
p 4
556 548.8 0
556 548.8 559.2
0 548.8 559.2
0 548.8 0
p 4
549.6 0 559.2
0 0 559.2
0 548.8 559.2
556 548.8 559.2
# green (right as seen from the camera)
f 0.14 0.45 0.091 1 0 0 0 1
p 4
0 0 559.2
0 0 0
0 548.8 0
0 548.8 559.2
# red
f 0.63 0.065 0.05 1 0 0 0 1
p 4
552.8 0 0
549.6 0 559.2
556 548.8 559.2
556 548.8 0
)";

constexpr const char* kBlocks = R"(# short block
f 0.725 0.71 0.68 1 0 0 0 1
p 4
130 165 65
82 165 225
240 165 272
290 165 114
p 4
290 0 114
290 165 114
240 165 272
240 0 272
p 4
130 0 65
130 165 65
290 165 114
290 0 114
p 4
82 0 225
82 165 225
130 165 65
130 0 65
p 4
240 0 272
240 165 272
82 165 225
82 0 225
# tall block
p 4
423 330 247
265 330 296
314 330 456
472 330 406
p 4
423 0 247
423 330 247
472 330 406
472 0 406
p 4
472 0 406
472 330 406
314 330 456
314 0 456
p 4
314 0 456
314 330 456
265 330 296
265 0 296
p 4
265 0 296
265 330 296
423 330 247
423 0 247
)";

constexpr const char* kSpheres = R"(# mirror sphere
f 1 1 1 0 0.9 0 0 1
s 185 82.5 169 82.5
# glass sphere
f 1 1 1 0 0.1 0 0.9 1.5
s 368 82.5 351 82.5
)";

}  // namespace

std::string generate_cornell(int size) { return std::string(kRoom) + (size == 2 ? kSpheres : kBlocks); }

}  // namespace raypack::spd
