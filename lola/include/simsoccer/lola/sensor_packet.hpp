// LoLA's sensor map (robot -> team code), as a Nao V6 sends it every 12 ms:
// one MessagePack map of 13 keys, exactly 896 bytes, constant layout. Team
// code reads exactly 896 bytes and some parsers keep byte offsets from the
// first packet, so the encoding is hand-written: float32 everywhere (0.0
// too; msgpack-c 4.1.3 would pack whole-number floats as integers), Status
// as positive fixints, RobotConfig as four strings of 20/5/20/5 characters.
// Layout, units and signs: docs/lola.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "simsoccer/world/sensor_frame.hpp"

namespace simsoccer::lola {

inline constexpr std::size_t kSensorPacketBytes = 896;
inline constexpr std::size_t kJoints = 25;  // LoLA's joint arrays (Nao order)
inline constexpr std::size_t kIdChars = 20, kVersionChars = 5;
// LoLA's cycle: one sensor map every 12 ms.
inline constexpr double kCycleSeconds = 0.012;

// `RobotConfig`: what the robot says it is. The head id P0000000000000000000
// is the simulator's by convention (the Webots LoLA controller's; Bembelbots
// read it as "simulator").
struct RobotIdentity {
  std::string body_id, body_version = "6.0.0";
  std::string head_id = "P0000000000000000000", head_version = "6.0.0";
};
// A body id unique in the match: "SIMSOCCER" + team and player, 20 characters.
RobotIdentity defaultIdentity(int team_number, int player);
// Throws std::invalid_argument naming the field when a string has the wrong
// length, is not printable ASCII, or a version does not start with a digit.
void checkIdentity(const RobotIdentity& id);

// `Battery`: [charge 0..1, status word, current A, temperature deg C].
struct Battery {
  float charge = 1.0f;
  float status = -32708.0f;  // a discharging Nao's status word (bit 0x80 clear: not charging)
  float current = 0.0f;      // A, negative while discharging
  float temperature = 30.0f;
};

// The Nao V6 battery (21.6 V, 2.9 Ah): drained by the motors' currents and
// the head's computer.
class BatteryModel {
 public:
  explicit BatteryModel(double initial_charge = 1.0, double capacity_ah = 2.9,
                        double idle_current_a = 1.0);
  // One cycle of `dt` seconds with the frame's motor currents.
  void update(const world::SensorFrame& frame, double dt);
  Battery reading() const { return reading_; }

 private:
  double capacity_coulomb_, idle_current_a_, charge_;
  Battery reading_;
};

// The 13 values in LoLA's units and signs (converted from a SensorFrame).
struct SensorValues {
  std::array<float, kJoints> position{}, stiffness{}, current{}, temperature{};
  std::array<uint8_t, kJoints> status{};  // 0..3
  std::array<float, 3> accelerometer{};   // m/s^2, LoLA's raw sign: about (0, 0, -9.81) upright
  std::array<float, 3> gyroscope{};       // rad/s, torso frame
  std::array<float, 2> angles{};          // torso roll, pitch (rad)
  std::array<float, world::kFsrs> fsr{};  // kg: L FL FR RL RR, R FL FR RL RR
  std::array<float, world::kTouchSensors> touch{};  // 0 or 1, LoLA's Touch order
  std::array<float, 2> sonar{};                     // left, right (m)
  Battery battery;
};
SensorValues fromFrame(const world::SensorFrame& frame, const Battery& battery);

using SensorPacket = std::array<uint8_t, kSensorPacketBytes>;
// Key order as in the one captured real packet (NaoTH's printout):
// RobotConfig, Accelerometer, Angles, Battery, Current, FSR, Gyroscope,
// Position, Sonar, Stiffness, Temperature, Touch, Status.
// Throws std::invalid_argument when the identity is malformed.
SensorPacket encodeSensorPacket(const SensorValues& values, const RobotIdentity& id);

}  // namespace simsoccer::lola
