// What a simulated Nao's body reports to its software each control period:
// the LoLA sensor map (nao.md 7.2) as a plain fixed-size struct, filled
// without heap allocation, stamped with simulation time.
//
// Arrays indexed by actuator follow the robot model's actuator order (LoLA
// order on a Nao: 0 HeadYaw ... 24 RHand; the SDK's order on a Booster K1).
// Sensors a robot lacks (a K1 has no foot pressure sensors, bumpers or
// sonars) stay 0. Frames: IMU values in the torso
// frame (x forward, y left, z up); centres of pressure in each foot's sole
// frame (ankle projected to the sole), metres.
#pragma once

#include <array>
#include <cstdint>

#include "simsoccer/protocol/wire.hpp"

namespace simsoccer::world {

// The protocol's layout (a frame goes to the agents as it is). kActuators is
// the capacity of the per-actuator arrays (a Nao's 25 LoLA slots); a robot
// with fewer actuators (a Booster K1 has 22) fills the first ones.
constexpr std::size_t kActuators = protocol::kActuators;
constexpr std::size_t kFsrs = protocol::kFsrs;  // L FL, FR, RL, RR, R FL, FR, RL, RR
constexpr std::size_t kTouchSensors = protocol::kTouchSensors;
constexpr std::size_t kSonarEchoes = protocol::kSonarEchoes;

// LoLA `Touch` order.
enum class Touch : uint8_t {
  ChestButton,
  HeadFront,
  HeadMiddle,
  HeadRear,
  LFootBumperLeft,
  LFootBumperRight,
  LHandBack,
  LHandLeft,
  LHandRight,
  RFootBumperLeft,
  RFootBumperRight,
  RHandBack,
  RHandLeft,
  RHandRight,
};

struct SensorFrame {
  uint64_t tick = 0;  // control period index (1 = the first period's end)
  double time = 0.0;  // s of simulation at the end of the period

  // Joints, per actuator (absent actuators stay 0).
  std::array<float, kActuators> position{};     // rad, quantised to the encoder
  std::array<float, kActuators> velocity{};     // rad/s over the period
  std::array<float, kActuators> target{};       // rad, the command in force
  std::array<float, kActuators> stiffness{};    // 0..1
  std::array<float, kActuators> current{};      // A, mean over the period
  std::array<float, kActuators> temperature{};  // deg C
  std::array<uint8_t, kActuators> status{};     // 0 normal .. 3 critical (temperature)

  // Inertial unit (torso frame).
  std::array<float, 3> accelerometer{};  // m/s^2, specific force: +9.81 z at rest
  std::array<float, 3> gyroscope{};      // rad/s
  std::array<float, 3> angles{};         // roll, pitch, yaw of the torso, rad

  // Feet, averaged over the period.
  std::array<float, kFsrs> fsr{};                            // N
  std::array<float, kFsrs> fsr_kg{};                         // kg (LoLA's unit): N / 9.81
  std::array<float, 2> foot_weight{};                        // N per foot (left, right)
  std::array<std::array<float, 2>, 2> centre_of_pressure{};  // per foot, x y in m

  // Sonars (left, right): nearest echo and up to 10 echoes, sorted.
  std::array<float, 2> sonar{};
  std::array<std::array<float, kSonarEchoes>, 2> sonar_echoes{};
  std::array<uint8_t, 2> sonar_echo_count{};

  std::array<uint8_t, kTouchSensors> touch{};  // 0 or 1, LoLA order
};

}  // namespace simsoccer::world
