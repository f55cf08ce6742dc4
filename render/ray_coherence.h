#pragma once
// Whether a batch of secondary rays is better traced as packets or as one
// stream (Accel::intersect_stream): the renderers ask it per batch.
#include <cstddef>
#include <span>

#include "kernels/ray.h"

namespace raypack {

/// Whether fewer than a quarter of the packets of 16 consecutive rays of
/// `rays` lie in one direction octant: rays that packets and their groups
/// cannot bound together (a group needs one octant), and that a stream
/// walks faster. Over whole renders, 4.6% of rings' reflection packets and
/// 12.4% of balls' lie in one octant, 63-79% of gears', mount's and
/// teapot's. Per batch, at a half instead of a quarter, mount streamed two
/// batches of refracted rays (6% of its bounces) and rendered 5-10% slower;
/// gears 3-5% slower, balls and rings within noise.
inline bool incoherent(std::span<const Rayf> rays) {
    constexpr std::size_t kPacket = 16;
    auto octant = [](const Rayf& r) { return (r.dir.x < 0.0f) | ((r.dir.y < 0.0f) << 1) | ((r.dir.z < 0.0f) << 2); };
    std::size_t packets = 0, one_octant = 0;
    for (std::size_t first = 0; first + kPacket <= rays.size(); first += kPacket, ++packets) {
        const int o = octant(rays[first]);
        bool same = true;
        for (std::size_t i = first + 1; i < first + kPacket; ++i) same &= octant(rays[i]) == o;
        one_octant += same;
    }
    return 4 * one_octant < packets;
}

}  // namespace raypack
