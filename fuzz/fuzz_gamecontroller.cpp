// The GameController packet decoders (control v18, v19 and v20, return v4) on
// any datagram. A packet that decodes must encode and decode again to the
// same values (the HSL codes map to the SPL's and back consistently).
#include <cstddef>
#include <cstdint>
#include <span>

#include "simsoccer/referee/gamecontroller.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace simsoccer::referee;
  const std::span<const uint8_t> bytes(data, size);
  try {
    int version = 0;
    const ControlData d = decodeAnyControl(bytes, &version);
    const ControlData again = decodeAnyControl(encodeControl(d, version));
    if (!(decodeAnyControl(encodeControl(again, version)) == again)) __builtin_trap();
  } catch (const PacketError&) {
  }
  try {
    const ReturnData r = decodeReturn(bytes);
    if (!(decodeReturn(encode(r)) == r)) __builtin_trap();
  } catch (const PacketError&) {
  }
  return 0;
}
