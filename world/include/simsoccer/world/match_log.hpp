// The match log: a compact binary record of a game, one frame per control
// period (every robot's torso pose and joint angles, the ball, the game
// state as a GameController packet, the joint commands applied, the world's
// state hash) plus the referee's events. Enough to re-render any part of the
// game, and to re-run it through the physics with the recorded commands
// (the hashes must come out the same).
//
// File layout (little-endian): "SSMLOG\0\0", u32 format version, u32 header
// length, the header (key=value lines: scenario, seed, ...; then per robot
// "robot=team,number,joints"), then blocks: u32 raw length, u32 packed length,
// zlib-deflated frames. A block holds up to 100 frames and is written when
// full, so a run that stops early (Ctrl-C) leaves a valid, shorter log.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/world/world.hpp"

namespace simsoccer::world {

// 2: per robot the LED colours a LoLA client set (chest, left eye, right eye).
constexpr uint32_t kMatchLogVersion = 2;
// Joint commands are applied at this resolution (rad; stiffness in 1/255),
// so that the log holds exactly what the physics got.
constexpr double kCommandResolution = 1e-4;
inline double quantizeCommand(double rad) {
  return static_cast<double>(static_cast<int16_t>(
             std::max(-32767.0, std::min(32767.0, std::round(rad / kCommandResolution))))) *
         kCommandResolution;
}
inline double quantizeStiffness(double s) {
  return std::round(std::max(0.0, std::min(1.0, s)) * 255.0) / 255.0;
}

struct LogEvent {
  double time = 0.0;
  std::string type;
  int team = -1, player = 0;
  std::string detail;
};

struct LoggedRobot {
  Pose torso = Pose::Identity();
  std::vector<double> joints;                 // rad, per body joint (int16, 1e-4 rad)
  std::array<double, 25> command_position{};  // rad, actuator order, as applied
  std::array<double, 25> command_stiffness{};
  bool commanded = false;  // a command was applied this period
  // The chest, left eye and right eye colours (RGB 0..255) a robot's
  // software set through LoLA; none: no LED commands (drawn grey).
  std::optional<std::array<uint8_t, 9>> leds;
};

struct LogFrame {
  uint64_t tick = 0;
  double time = 0.0;
  std::vector<uint8_t> game;  // GameController packet (empty: no referee)
  Pose ball = Pose::Identity();
  std::vector<LoggedRobot> robots;
  uint64_t state_hash = 0;  // World::stateHash() after the period
  std::vector<LogEvent> events;
};

struct LogRobotInfo {
  int team = 0, number = 0, joints = 0;
};

struct MatchLogHeader {
  std::map<std::string, std::string> values;  // scenario, seed, config, config_hash, ...
  std::vector<LogRobotInfo> robots;
};

class MatchLogWriter {
 public:
  MatchLogWriter(const std::filesystem::path& file, const MatchLogHeader& header);
  ~MatchLogWriter();  // flushes
  void write(const LogFrame& frame);
  void flush();  // the frames so far as a block (the file stays valid)
  uint64_t frames() const { return frames_; }
  uint64_t bytes() const { return bytes_; }

 private:
  std::ofstream out_;
  std::vector<uint8_t> block_;
  int in_block_ = 0;
  uint64_t frames_ = 0, bytes_ = 0;
};

class MatchLogReader {
 public:
  // Throws std::runtime_error naming the file and what is wrong.
  explicit MatchLogReader(const std::filesystem::path& file);
  const MatchLogHeader& header() const { return header_; }
  // The next frame; false at the end. Throws std::runtime_error naming the
  // file for a corrupt block or frame.
  bool next(LogFrame& frame);
  // Once next() returned false: the byte where the log was cut inside a
  // block (the writer was stopped; the frames after it are lost), if it was.
  std::optional<uint64_t> truncatedAt() const { return truncated_at_; }

 private:
  bool readBlock();
  bool readFrame(LogFrame& frame);
  uint64_t file_size_ = 0;
  std::optional<uint64_t> truncated_at_;
  std::filesystem::path file_;
  std::ifstream in_;
  MatchLogHeader header_;
  std::vector<uint8_t> block_;
  size_t pos_ = 0;
};

// A frame of the world as it is now, with the commands applied in the period
// that led to it (per robot; `commanded` false: none was).
LogFrame captureFrame(const World& world, uint64_t tick,
                      const std::vector<std::array<double, 25>>& positions,
                      const std::vector<std::array<double, 25>>& stiffness,
                      const std::vector<bool>& commanded);
// Puts the world into a logged frame's poses (joints at rest; for rendering).
void applyFrame(World& world, const LogFrame& frame);

}  // namespace simsoccer::world
