// A robot description (Nao H25, Nao H21, ...) loaded from YAML: the physical
// model the engine simulates plus what the robot's software sees of it: the
// actuator order of its command/sensor arrays, hands, sensor frames and
// named poses.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "simsoccer/engine/model.hpp"

namespace simsoccer::robots {

using engine::Pose;

// Where each entry of the robot's actuator arrays (LoLA order on a Nao) goes.
struct Actuator {
  enum class Kind { Joint, Hand, Absent };
  std::string name;
  Kind kind = Kind::Absent;
  int index = -1;  // joint index in the body model, or hand index
};

// A gripper without a physical hinge (massless fingers): commanded and
// sensed, rigid for contacts.
struct Hand {
  std::string name;
  int link = -1;
  double lower = 0.0, upper = 1.0;
  int motor = -1;
  double speed = 2.0;  // range units per second (0..1 in 0.5 s)
};

struct SensorFrame {
  std::string name;
  std::string type;  // accelerometer, gyroscope, camera, sonar, fsr, bumper, touch
  int link = -1;
  Pose pose = Pose::Identity();  // in the link's joint frame (a camera looks along x)
  double horizontal_fov = 0.0, vertical_fov = 0.0;  // rad, cameras only
};

// Sensor hardware characteristics (not placement: that is SensorFrame).
struct SensorSpec {
  int encoder_bits = 12;
  double gyro_range = 8.727;                              // rad/s, +-
  double accel_range = 19.62;                             // m/s^2, +-
  double sonar_min_range = 0.20, sonar_max_range = 0.80;  // m
  double sonar_cone_angle = 1.0472;                       // rad, full cone
  double sonar_no_echo_value = 5.0;                       // m
  int sonar_max_echoes = 10;
  double sonar_max_incidence = 0.96;  // rad from the surface normal
  double ambient_temperature = 25.0;  // deg C
  double temperature_hot = 70.0, temperature_very_hot = 80.0, temperature_critical = 90.0;
};

// One leg, for software that walks and kicks: its foot link and the joints
// from the trunk down to it (kinematic order, every hinge of the chain,
// mimic joints included).
struct LegChain {
  int foot_link = -1;
  std::vector<int> joints;
};

struct RobotModel {
  std::string name;
  std::string source_file;
  std::shared_ptr<const engine::ArticulatedModel> body;
  std::vector<Actuator> actuators;  // the robot's command order
  std::vector<Hand> hands;
  std::vector<SensorFrame> sensors;
  SensorSpec sensor_spec;
  std::map<std::string, std::vector<double>> poses;  // per body joint, rad
  // The legs (left, right) from the file's `legs: {left: FOOT, right: FOOT}`;
  // empty chains where the file names none.
  std::array<LegChain, 2> legs;
  bool hasLegs() const { return legs[0].foot_link >= 0; }
  // Down (fallen) with the torso origin below this height above the ground (m): the
  // file's `fallen_torso_height`, under the robot's own walk, crouch and block (a
  // Nao's torso stands at about 0.29 m, a Booster K1's at 0.51).
  double fallen_torso_height = 0.0;

  // Joint angles (one per body joint) of a named pose; throws if unknown.
  const std::vector<double>& pose(const std::string& pose_name) const;
  int actuatorIndex(const std::string& actuator_name) const;  // -1 if absent
  const SensorFrame* sensor(const std::string& sensor_name) const;
  // The robot's cameras in the description's order (a Nao: top, bottom).
  std::size_t cameraCount() const { return camera_sensors.size(); }
  const SensorFrame& camera(std::size_t k) const { return sensors.at(camera_sensors.at(k)); }
  std::vector<std::size_t> camera_sensors;  // indices into sensors
  // Depth of the lowest point of any collision shape (the soles, standing)
  // below the torso origin at the given joint angles, torso upright.
  double soleDepth(const std::vector<double>& joint_positions) const;
};

// Loads and validates a robot file; throws engine::ConfigError naming the
// file, key path and reason.
RobotModel loadRobotModel(const std::filesystem::path& file);

}  // namespace simsoccer::robots
