// A strict reader of LoLA sensor maps, written for the tests from what team
// code accepts (docs/lola.md), independent of the simulator's encoder: as
// B-Human's parser it takes only fixmap, fixstr keys, float32 values,
// positive-fixint Status, fixarray/array16; as HULKs' it needs every key;
// as Bembelbots' it refuses any other key; as Nao Devils' it needs exactly
// 896 bytes.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace simsoccer::test {

struct LolaSensors {
  std::map<std::string, std::vector<float>> floats;  // key -> values
  std::vector<int> status;
  std::array<std::string, 4> robot_config;
  const std::vector<float>& operator[](const std::string& key) const { return floats.at(key); }
};

inline LolaSensors readLolaSensors(std::span<const uint8_t> bytes) {
  if (bytes.size() != 896)
    throw std::runtime_error("packet is " + std::to_string(bytes.size()) + " bytes, not 896");
  std::size_t at = 0;
  const auto fail = [&](const std::string& what) {
    throw std::runtime_error(what + " at byte " + std::to_string(at));
  };
  const auto next = [&]() -> uint8_t {
    if (at >= bytes.size()) fail("packet ends early");
    return bytes[at++];
  };
  const auto fixstr = [&]() {
    const uint8_t h = next();
    if ((h & 0xe0) != 0xa0) fail("not a fixstr");
    std::string s;
    for (int i = 0; i < (h & 0x1f); ++i) s.push_back(static_cast<char>(next()));
    return s;
  };
  const auto arrayLength = [&]() -> std::size_t {
    const uint8_t h = next();
    if ((h & 0xf0) == 0x90) return h & 0x0f;
    if (h != 0xdc) fail("not an array");
    const std::size_t hi = next();
    return (hi << 8) | next();
  };
  const std::map<std::string, std::size_t> lengths = {
      {"RobotConfig", 4}, {"Accelerometer", 3}, {"Angles", 2},    {"Battery", 4},
      {"Current", 25},    {"FSR", 8},           {"Gyroscope", 3}, {"Position", 25},
      {"Sonar", 2},       {"Stiffness", 25},    {"Temperature", 25}, {"Touch", 14},
      {"Status", 25}};
  if (next() != 0x8d) fail("not a fixmap of 13 keys");
  LolaSensors out;
  std::map<std::string, bool> seen;
  for (int k = 0; k < 13; ++k) {
    const std::string key = fixstr();
    if (!lengths.count(key)) fail("unknown key '" + key + "'");
    if (seen[key]) fail("key '" + key + "' twice");
    seen[key] = true;
    const std::size_t n = arrayLength();
    if (n != lengths.at(key)) fail("key '" + key + "' has " + std::to_string(n) + " values");
    for (std::size_t i = 0; i < n; ++i) {
      if (key == "RobotConfig") {
        out.robot_config[i] = fixstr();
      } else if (key == "Status") {
        const uint8_t v = next();
        if (v > 0x7f) fail("Status is not a positive fixint");
        out.status.push_back(v);
      } else {
        if (next() != 0xca) fail("'" + key + "' value is not a float32");
        uint32_t bits = 0;
        for (int b = 0; b < 4; ++b) bits = (bits << 8) | next();
        float f;
        std::memcpy(&f, &bits, sizeof f);
        out.floats[key].push_back(f);
      }
    }
  }
  if (at != bytes.size()) fail("bytes after the map");
  const std::array<std::size_t, 4> config_lengths = {20, 5, 20, 5};
  for (std::size_t i = 0; i < 4; ++i)
    if (out.robot_config[i].size() != config_lengths[i]) fail("RobotConfig string of wrong length");
  return out;
}

}  // namespace simsoccer::test
