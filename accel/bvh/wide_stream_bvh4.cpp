// Stream traversal of the BVH4 (accel/bvh/wide_stream_traversal.h), one file
// per tree width to keep compile times bounded.
#include "accel/bvh/wide_stream_traversal.h"

namespace raypack {

#if defined(__AVX512BW__)
template void wide_trace_stream<4, 8, false>(const WideBvh<4, 8>&, const Scene&, KernelChoice, const WidePacketConfig&,
                                             std::span<const Rayf>, std::span<Hitf>, std::span<std::uint8_t>);
template void wide_trace_stream<4, 8, true>(const WideBvh<4, 8>&, const Scene&, KernelChoice, const WidePacketConfig&,
                                            std::span<const Rayf>, std::span<Hitf>, std::span<std::uint8_t>);
#endif

}  // namespace raypack
