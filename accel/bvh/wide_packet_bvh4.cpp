// Packet traversal of the BVH4 (accel/bvh/wide_packet.h), one file per
// tree width to keep compile times bounded.
#include "accel/bvh/wide_group_traversal.h"

namespace raypack {

#if defined(__SSE4_2__) && defined(__AVX2__)
template void wide_trace_packets<4, 8, 4>(const WideBvh<4, 8>&, const Scene&, KernelChoice, const WidePacketConfig&,
                                           std::span<const Rayf>, std::span<Hitf>);
template void wide_occluded_packets<4, 8, 4>(const WideBvh<4, 8>&, const Scene&, KernelChoice, const WidePacketConfig&,
                                              std::span<const Rayf>, std::span<std::uint8_t>);
#endif
#if defined(__AVX2__)
template void wide_trace_packets<4, 8, 8>(const WideBvh<4, 8>&, const Scene&, KernelChoice, const WidePacketConfig&,
                                           std::span<const Rayf>, std::span<Hitf>);
template void wide_occluded_packets<4, 8, 8>(const WideBvh<4, 8>&, const Scene&, KernelChoice, const WidePacketConfig&,
                                              std::span<const Rayf>, std::span<std::uint8_t>);
#endif
#if defined(__AVX512BW__)
template void wide_trace_packets<4, 8, 16>(const WideBvh<4, 8>&, const Scene&, KernelChoice, const WidePacketConfig&,
                                           std::span<const Rayf>, std::span<Hitf>);
template void wide_occluded_packets<4, 8, 16>(const WideBvh<4, 8>&, const Scene&, KernelChoice, const WidePacketConfig&,
                                              std::span<const Rayf>, std::span<std::uint8_t>);
#endif

}  // namespace raypack
