// A reader of GameController control packets written for the tests from the
// official layouts (GameController3's RoboCupGameControlData.h, version 18,
// 118 bytes; the HSL GameController's, version 19, 198 bytes, and version 20,
// 158 bytes), by absolute byte offsets, independent of the simulator's encoder
// and decoder.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace simsoccer::test {

struct GcPlayer {
  int penalty = 0, secs_till_unpenalised = 0, warnings = -1, cautions = -1;  // HSL only
};
struct GcTeam {
  int number = 0, field_player_colour = 0, goalkeeper_colour = 0, goalkeeper = 0, score = 0;
  int penalty_shot = 0, single_shots = 0, message_budget = 0;
  std::vector<GcPlayer> players;  // 20
};
struct GcPacket {
  int version = 0, packet_number = 0, players_per_team = 0;
  int competition_phase = -1;  // v18 only
  int competition_type = 0;
  int stopped = -1;  // HSL (v19, v20) only
  int game_phase = 0, state = 0, set_play = 0, first_half = 0, kicking_team = 0;
  int secs_remaining = 0, secondary_time = 0;
  GcTeam teams[2];
};

inline GcPacket readGcPacket(std::span<const uint8_t> b) {
  if (b.size() < 5 || std::memcmp(b.data(), "RGme", 4) != 0)
    throw std::runtime_error("not an RGme packet");
  GcPacket p;
  p.version = b[4];
  const std::size_t size = p.version == 18   ? 118
                           : p.version == 19 ? 198
                           : p.version == 20 ? 158
                                             : 0;
  if (size == 0) throw std::runtime_error("version " + std::to_string(p.version));
  if (b.size() != size)
    throw std::runtime_error("version " + std::to_string(p.version) + " packet of " +
                             std::to_string(b.size()) + " bytes, expected " + std::to_string(size));
  const auto u16 = [&](std::size_t at) { return b[at] | (b[at + 1] << 8); };
  const auto i16 = [&](std::size_t at) { return static_cast<int>(static_cast<int16_t>(u16(at))); };
  p.packet_number = b[5];
  p.players_per_team = b[6];
  if (p.version == 18) {
    p.competition_phase = b[7];
    p.competition_type = b[8];
  } else {
    p.competition_type = b[7];
    p.stopped = b[8];
  }
  p.game_phase = b[9];
  p.state = b[10];
  p.set_play = b[11];
  p.first_half = b[12];
  p.kicking_team = b[13];
  p.secs_remaining = i16(14);
  p.secondary_time = i16(16);
  // RobotInfo: penalty, secsTillUnpenalised; v19 warnings, cautions; v20 cautions.
  const std::size_t player_size = p.version == 18 ? 2 : p.version == 19 ? 4 : 3;
  const std::size_t team_size = 10 + 20 * player_size;  // 50, 90 or 70
  for (int t = 0; t < 2; ++t) {
    const std::size_t at = 18 + static_cast<std::size_t>(t) * team_size;
    GcTeam& team = p.teams[t];
    team.number = b[at];
    team.field_player_colour = b[at + 1];
    team.goalkeeper_colour = b[at + 2];
    team.goalkeeper = b[at + 3];
    team.score = b[at + 4];
    team.penalty_shot = b[at + 5];
    team.single_shots = u16(at + 6);
    team.message_budget = u16(at + 8);
    for (std::size_t n = 0; n < 20; ++n) {
      const std::size_t q = at + 10 + n * player_size;
      GcPlayer pl;
      pl.penalty = b[q];
      pl.secs_till_unpenalised = b[q + 1];
      if (p.version == 19) {
        pl.warnings = b[q + 2];
        pl.cautions = b[q + 3];
      } else if (p.version == 20) {
        pl.cautions = b[q + 2];
      }
      team.players.push_back(pl);
    }
  }
  return p;
}

}  // namespace simsoccer::test
