// The GameController packets' field-by-field serialisation (no struct layout
// is trusted): a little-endian writer and reader over a fixed buffer, and a
// TeamInfo in v18's layout (2-byte RobotInfo), v19's (4 bytes, HSL codes) or v20's (3 bytes,
// HSL codes).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "simsoccer/referee/gamecontroller.hpp"

namespace simsoccer::referee {
namespace {

// Little-endian field writer/reader over a fixed buffer.
class Out {
 public:
  explicit Out(std::span<uint8_t> b) : b_(b) {}
  void u8(uint8_t v) { b_[pos_++] = v; }
  void u16(uint16_t v) {
    u8(static_cast<uint8_t>(v & 0xff));
    u8(static_cast<uint8_t>(v >> 8));
  }
  void i16(int16_t v) { u16(static_cast<uint16_t>(v)); }
  void f32(float v) {
    uint32_t u;
    std::memcpy(&u, &v, 4);
    for (int i = 0; i < 4; ++i) u8(static_cast<uint8_t>(u >> (8 * i)));
  }
  void bytes(const char* s, size_t n) {
    for (size_t i = 0; i < n; ++i) u8(static_cast<uint8_t>(s[i]));
  }
  size_t pos() const { return pos_; }

 private:
  std::span<uint8_t> b_;
  size_t pos_ = 0;
};

class In {
 public:
  explicit In(std::span<const uint8_t> b) : b_(b) {}
  uint8_t u8() { return b_[pos_++]; }
  uint16_t u16() {
    const uint16_t lo = u8();
    return static_cast<uint16_t>(lo | (u8() << 8));
  }
  int16_t i16() { return static_cast<int16_t>(u16()); }
  float f32() {
    uint32_t u = 0;
    for (int i = 0; i < 4; ++i) u |= static_cast<uint32_t>(u8()) << (8 * i);
    float v;
    std::memcpy(&v, &u, 4);
    return v;
  }
  size_t pos() const { return pos_; }

 private:
  std::span<const uint8_t> b_;
  size_t pos_ = 0;
};

// `version`: 18 (SPL), 19 or 20 (HSL).
void writeTeam(Out& o, const TeamInfo& t, int version) {
  const bool hsl = version != gc::kControlVersion;
  o.u8(t.team_number);
  o.u8(t.field_player_colour);
  o.u8(t.goalkeeper_colour);
  o.u8(t.goalkeeper);
  o.u8(t.score);
  o.u8(t.penalty_shot);
  o.u16(t.single_shots);
  o.u16(t.message_budget);
  for (const RobotInfo& r : t.players) {
    o.u8(hsl ? hsl::penaltyFromSpl(r.penalty, version) : r.penalty);
    o.u8(r.secs_till_unpenalised);
    if (version == hsl::kVersion19) o.u8(r.warnings);
    if (hsl) o.u8(r.cautions);
  }
}

TeamInfo readTeam(In& in, int version) {
  const bool hsl = version != gc::kControlVersion;
  TeamInfo t;
  t.team_number = in.u8();
  t.field_player_colour = in.u8();
  t.goalkeeper_colour = in.u8();
  t.goalkeeper = in.u8();
  t.score = in.u8();
  t.penalty_shot = in.u8();
  t.single_shots = in.u16();
  t.message_budget = in.u16();
  for (RobotInfo& r : t.players) {
    r.penalty = in.u8();
    if (hsl) r.penalty = hsl::penaltyToSpl(r.penalty, version);
    r.secs_till_unpenalised = in.u8();
    if (version == hsl::kVersion19) r.warnings = in.u8();
    if (hsl) r.cautions = in.u8();
  }
  return t;
}

}  // namespace
}  // namespace simsoccer::referee
