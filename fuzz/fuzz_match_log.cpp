// The match-log reader on any file: every header and block length comes
// from the file, so memory must stay bounded by the file's size and every
// failure must be a std::runtime_error naming the file.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "fuzz_input.hpp"
#include "simsoccer/world/match_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace simsoccer;
  const auto file = fuzz::asFile(data, size, "match.log");
  try {
    world::MatchLogReader log(file);
    world::LogFrame frame;
    while (log.next(frame)) {
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
