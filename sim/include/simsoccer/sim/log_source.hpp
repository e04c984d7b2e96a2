// A match log as a command source: replays the commands applied in each
// recorded period, through the same gate as any other source (a corrupt or
// edited log cannot put a NaN into the world).
#pragma once

#include <filesystem>

#include "simsoccer/sim/command.hpp"
#include "simsoccer/world/match_log.hpp"

namespace simsoccer::sim {

class LogSource : public CommandSource {
 public:
  explicit LogSource(const std::filesystem::path& file);
  // Reads the next recorded period; false at the end of the log.
  bool next();
  // The recorded period whose commands the next collect gives.
  const world::LogFrame& frame() const { return frame_; }
  // Commands in the log that the gate refused.
  uint64_t refused() const { return refused_; }

  void observe(const Observation&) override {}
  void collect(uint64_t tick, CommandGate& gate, std::span<CommandSlot> slots) override;

 private:
  world::MatchLogReader reader_;
  world::LogFrame frame_;
  uint64_t refused_ = 0;
};

}  // namespace simsoccer::sim
