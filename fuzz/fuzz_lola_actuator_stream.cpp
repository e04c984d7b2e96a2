// The LoLA actuator-map parser on anything a client could send, split at a
// point the input chooses (maps arrive in pieces). StreamError is the
// expected refusal; anything else (a crash, a leak, undefined behaviour,
// unbounded memory) is a finding.
#include <cstddef>
#include <cstdint>
#include <span>

#include "simsoccer/lola/actuator_stream.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace simsoccer;
  lola::ActuatorStream stream{lola::ActuatorValues{}};
  const std::span<const uint8_t> all(data, size);
  const size_t cut = size == 0 ? 0 : data[0] % (size + 1);
  try {
    stream.feed(all.first(cut));
    stream.feed(all.subspan(cut));
  } catch (const lola::StreamError&) {
  }
  if (stream.buffered() > 64 * 1024 + 4096) __builtin_trap();  // the promised bound
  return 0;
}
