#pragma once
// Embree's ray types and calls by packet width, so that code over K can name
// them: nothing but Embree's own API (bench/tools/embree_direct.cpp uses it
// too, and its timed path must hold no raypack code).
#include <embree3/rtcore.h>

namespace raypack {

/// Embree's packet types carry their own alignment (RTC_ALIGN(16/32/64) on
/// RTCRayHit4/8/16); the valid masks need the same.
template <int K> struct EmbreePacket;
template <> struct EmbreePacket<1> {
    using RayHit = RTCRayHit;
    using Ray = RTCRay;
    static void intersect(const int*, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect1(s, c, r); }
    static void occluded(const int*, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded1(s, c, r); }
};
template <> struct EmbreePacket<4> {
    using RayHit = RTCRayHit4;
    using Ray = RTCRay4;
    static void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect4(v, s, c, r); }
    static void occluded(const int* v, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded4(v, s, c, r); }
};
template <> struct EmbreePacket<8> {
    using RayHit = RTCRayHit8;
    using Ray = RTCRay8;
    static void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect8(v, s, c, r); }
    static void occluded(const int* v, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded8(v, s, c, r); }
};
template <> struct EmbreePacket<16> {
    using RayHit = RTCRayHit16;
    using Ray = RTCRay16;
    static void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect16(v, s, c, r); }
    static void occluded(const int* v, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded16(v, s, c, r); }
};

}  // namespace raypack
