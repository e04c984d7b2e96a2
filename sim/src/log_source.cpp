#include "simsoccer/sim/log_source.hpp"

namespace simsoccer::sim {

LogSource::LogSource(const std::filesystem::path& file) : reader_(file) {}

bool LogSource::next() {
  return reader_.next(frame_);
}

void LogSource::collect(uint64_t, CommandGate& gate, std::span<CommandSlot> slots) {
  for (size_t r = 0; r < slots.size() && r < frame_.robots.size(); ++r) {
    const world::LoggedRobot& logged = frame_.robots[r];
    if (!logged.commanded) continue;
    // The log holds what was applied in that period: the answer of this one.
    if (auto c = gate.check(static_cast<world::RobotId>(r),
                            std::span<const double>(logged.command_position),
                            std::span<const double>(logged.command_stiffness))) {
      slots[r] = {Answer::Given, *c};
    } else {
      ++refused_;
    }
  }
}

}  // namespace simsoccer::sim
