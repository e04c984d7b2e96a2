// LoLA's actuator direction (team code -> robot): MessagePack maps on a byte
// stream with no framing. Maps come whole or split over several reads,
// several per cycle, and partial (a key that is absent keeps its last value);
// numbers come as float32, float64 or integers of any width (clients built
// with msgpack-c 4.1.2+ send whole-number floats as integers); `Sonar` as
// bools or numbers; unknown keys are ignored and counted. Parsed with
// msgpack-c's streaming unpacker under size limits, so no input can make it
// buffer more than one actuator map's worth.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

#include "simsoccer/lola/sensor_packet.hpp"

namespace simsoccer::lola {

// Every value a client can set, as last set.
struct ActuatorValues {
  std::array<float, kJoints> position{}, stiffness{};  // rad; 0..1 (clamped, as LoLA does)
  std::array<float, 3> chest{}, lfoot{}, rfoot{};      // RGB 0..1
  std::array<float, 24> leye{}, reye{};                // 8 reds, 8 greens, 8 blues
  std::array<float, 10> lear{}, rear{};                // ring segments
  std::array<float, 12> skull{};
  std::array<bool, 2> sonar{true, true};  // emitters on
  bool leds_set = false;                  // a Chest or eye colour was received
};

struct StreamCounts {
  uint64_t maps = 0;          // complete maps taken
  uint64_t joint_maps = 0;    // of them, maps that set Position or Stiffness (an answer to a cycle)
  uint64_t bad_maps = 0;      // maps refused whole: a known key with a wrong type or length
  uint64_t unknown_keys = 0;  // ignored keys
  uint64_t bytes = 0;
};

// The stream cannot be read on (not MessagePack, not a map, over the size
// limits): the session must end, the client may reconnect.
class StreamError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ActuatorStream {
 public:
  // `initial`: the values before the client sent any (the commands in force).
  explicit ActuatorStream(const ActuatorValues& initial);
  ~ActuatorStream();
  ActuatorStream(ActuatorStream&&) noexcept;
  ActuatorStream& operator=(ActuatorStream&&) noexcept;

  // Bytes as they arrive, kept until parsed. Throws StreamError when more
  // than 64 KiB wait (a real actuator map is under 1 KiB).
  void append(std::span<const uint8_t> bytes);
  // Parses the next complete map and merges it into values(): none when no
  // complete map waits; else whether it set joints (Position or Stiffness;
  // a map refused whole sets none). Throws StreamError.
  std::optional<bool> next();
  // append() and next() until no complete map waits; the number of maps.
  std::size_t feed(std::span<const uint8_t> bytes);
  const ActuatorValues& values() const { return values_; }
  // Puts the joint values back (a merged command the gate refused).
  void restoreJoints(const std::array<float, kJoints>& position,
                     const std::array<float, kJoints>& stiffness);
  const StreamCounts& counts() const { return counts_; }
  // Bytes received that are not yet a complete map.
  std::size_t buffered() const;

 private:
  struct Unpacker;
  std::unique_ptr<Unpacker> unpacker_;
  ActuatorValues values_;
  StreamCounts counts_;
};

}  // namespace simsoccer::lola
