// A world scenario: which field and robot models, where the robots and the
// ball start, physics settings and the seed. Loaded from YAML (see
// configs/) or built in code (the benchmarks), validated either way.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "simsoccer/engine/model.hpp"

namespace simsoccer::world {

struct RobotPlacement {
  int team = 0;                   // 0 or 1
  int number = 1;                 // player number, unique within a team
  double x = 0.0, y = 0.0;        // m, field frame
  double yaw = 0.0;               // rad, heading in the field frame
  std::string posture = "stand";  // named pose of the robot model
  std::string model_file;         // empty: the scenario's robot_model
};

struct PhysicsConfig {
  double dt = 0.005;              // s
  double control_period = 0.010;  // s, a whole multiple of dt
  int solver_iterations = 10;
  int friction_directions = 1;  // per contact: 1 (along the slip) or 2 (a pyramid)
  double gravity = -9.81;       // m/s^2 along z
};

// Standard deviations of the seeded random perturbations applied when the
// robots are placed (0 = exact placement).
struct PlacementNoise {
  double position = 0.0;  // m
  double yaw = 0.0;       // rad
  double joints = 0.0;    // rad
};

// Sensor simulation settings (the hardware's own numbers are in the robot
// model). Noise is white, per axis, from the scenario seed; off by default.
struct SensorSettings {
  bool enabled = true;          // false: no sensor frames (pure physics runs)
  int sonar_rays = 9;           // rays per sonar cone
  double sonar_period = 0.060;  // s between sonar updates, a multiple of the control period
  engine::Vec3 gyro_noise = engine::Vec3::Zero();   // rad/s std dev
  engine::Vec3 gyro_bias = engine::Vec3::Zero();    // rad/s
  engine::Vec3 accel_noise = engine::Vec3::Zero();  // m/s^2 std dev
  engine::Vec3 accel_bias = engine::Vec3::Zero();   // m/s^2
  engine::Vec3 angle_noise = engine::Vec3::Zero();  // rad std dev (roll, pitch, yaw)
};

struct Scenario {
  std::string name;
  std::string source_file;  // for error messages; empty when built in code
  std::filesystem::path field_file;
  std::filesystem::path robot_model_file;
  PhysicsConfig physics;
  uint64_t seed = 1;
  PlacementNoise noise;
  SensorSettings sensors;
  engine::Vec3 ball_position{0.0, 0.0, -1.0};  // z < 0: resting on the ground
  engine::Vec3 ball_velocity = engine::Vec3::Zero();
  std::vector<RobotPlacement> robots;
};

// Reads and checks a scenario file (syntax, types, required keys).
// Model-dependent checks (placement on the field, postures) run when the
// World is built. Throws engine::ConfigError.
Scenario loadScenario(const std::filesystem::path& file);

}  // namespace simsoccer::world
