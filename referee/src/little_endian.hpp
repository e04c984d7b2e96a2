// Little-endian field writer/reader over a fixed buffer: the GameController
// packets are serialised field by field (no struct layout is trusted).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

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

}  // namespace
}  // namespace simsoccer::referee
