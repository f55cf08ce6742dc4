// The packet driver (accel/packet_driver.h) that every packet walk runs
// under: trace_in_sized_groups traces each packet exactly once, alone or in
// a group of consecutive packets no larger than its leader asks for, and
// stores each lane's hit at its own ray's place.
#include <gtest/gtest.h>

#include <cstddef>
#include <limits>
#include <vector>

#include "accel/packet_driver.h"

namespace raypack {
namespace {

template <int K>
void check_sized_groups() {
    constexpr int G = 8;
    // 23 full packets and a half one; ray i starts at x = i, so a packet
    // knows its place, and the packet at place p leads groups of p % 5
    // packets (0: alone; 5 and more: the cap G is not reached, 1: a group
    // of one).
    const std::size_t n = 23 * K + K / 2;
    const std::size_t packets = (n + K - 1) / K;
    std::vector<Rayf> rays(n);
    for (std::size_t i = 0; i < n; ++i) rays[i] = Rayf{{float(i), 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}};
    std::vector<Hitf> hits(n);
    std::vector<int> traced(packets, 0);
    auto place = [](const RayPacket<K>& ray) { return std::size_t(lane(ray.org[0], 0)) / K; };
    auto group_size = [&](const LoadedPacket<K>& p) { return int(place(p.ray) % 5); };
    // A hit per valid lane that names its ray: t = x + 1, prim = x.
    auto mark = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid) {
        ++traced[place(ray)];
        hit.t = select(valid, ray.org[0] + vfloat<K>(1.0f), hit.t);
        for (int l = 0; l < K; ++l)
            if ((mask_bits(valid) >> l) & 1u) hit.prim[l] = std::uint32_t(lane(ray.org[0], l));
    };
    std::vector<std::size_t> alone;
    std::size_t next = 0;  // the packet the next group or lone packet must start at
    trace_in_sized_groups<K, G, false>(
        rays, std::span(hits), RcpMethod::Exact, group_size,
        [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid, vmask<K>&) {
            EXPECT_EQ(place(ray), next);
            EXPECT_EQ(group_size(LoadedPacket<K>{ray, hit, valid, valid, 0}), 0);
            alone.push_back(place(ray));
            ++next;
            mark(ray, hit, valid);
        },
        [&](LoadedPacket<K>* p, int count) {
            const int size = group_size(p[0]);
            ASSERT_GE(count, 1);
            EXPECT_LE(count, size);
            // Full, unless the rays ran out.
            if (count < size) {
                EXPECT_EQ(place(p[0].ray) + std::size_t(count), packets);
            }
            for (int q = 0; q < count; ++q) {
                EXPECT_EQ(place(p[q].ray), next + std::size_t(q));
                mark(p[q].ray, p[q].hit, p[q].valid);
            }
            next += std::size_t(count);
        });
    EXPECT_EQ(next, packets);
    for (std::size_t q = 0; q < packets; ++q) EXPECT_EQ(traced[q], 1) << "packet " << q;
    for (std::size_t i = 0; i < n; ++i) {
        EXPECT_EQ(hits[i].t, float(i) + 1.0f) << "ray " << i;
        EXPECT_EQ(hits[i].prim, std::uint32_t(i)) << "ray " << i;
    }
    // Packets at places 0, 5, 10, ... asked to walk alone, and did; the
    // others only ever followed or led groups.
    for (std::size_t q : alone) EXPECT_EQ(q % 5, 0u);
    EXPECT_FALSE(alone.empty());
}

TEST(PacketDriver, SizedGroupsTraceEveryPacketOnceInOrder) {
    if constexpr (kWidthCompiled<4>) check_sized_groups<4>();
    if constexpr (kWidthCompiled<8>) check_sized_groups<8>();
    if constexpr (kWidthCompiled<16>) check_sized_groups<16>();
}

}  // namespace
}  // namespace raypack
