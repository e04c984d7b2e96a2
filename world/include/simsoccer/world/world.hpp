// The simulated world: a field, a ball and Nao robots in one physics engine,
// advanced at a fixed time step. The step count is the clock.
//
// Robots are addressed by index (RobotId), in scenario order. Commands are
// per robot, in the robot model's actuator order (LoLA order for a Nao),
// and hold until replaced.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "simsoccer/engine/physics_world.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/robots/robot_model.hpp"
#include "simsoccer/world/scenario.hpp"
#include "simsoccer/world/sensor_frame.hpp"
#include "simsoccer/world/sensor_system.hpp"

namespace simsoccer::world {

// A robot of the world, in scenario order (not its articulation in the engine).
using RobotId = engine::Id<struct RobotTag>;
using engine::Pose;
using engine::Vec3;

struct RobotInfo {
  int team = 0;
  int number = 0;
  std::shared_ptr<const robots::RobotModel> model;
  engine::ArticulationId body = 0;
};

struct RobotState {
  Pose torso = Pose::Identity();        // torso frame in the field frame
  Vec3 linear_velocity = Vec3::Zero();  // torso origin... root, world frame
  Vec3 angular_velocity = Vec3::Zero();
  std::vector<double> joint_positions;   // per body joint, rad
  std::vector<double> joint_velocities;  // rad/s
};

// The last robot that touched the ball.
struct BallTouch {
  RobotId robot = 0;
  int link = 0;       // the robot's link that touched it (model link index)
  uint64_t step = 0;  // physics step of the touch
};

struct WorldSnapshot {
  uint64_t step = 0;
  double time = 0.0;  // s
  std::vector<RobotState> robots;
  engine::RigidBodyState ball;
};

class World {
 public:
  explicit World(const Scenario& scenario);
  static World fromFile(const std::filesystem::path& scenario_file);

  const Scenario& scenario() const { return scenario_; }
  const fields::FieldModel& field() const { return *field_; }
  size_t robotCount() const { return robots_.size(); }
  const RobotInfo& robot(RobotId r) const { return robots_.at(r); }
  int stepsPerControlPeriod() const { return steps_per_control_; }
  // The control period under way (its number: the tick of SensorFrames and commands).
  uint64_t controlTick() const { return stepCount() / static_cast<uint64_t>(steps_per_control_); }

  // --- commands -----------------------------------------------------------------
  // Targets (rad) and stiffnesses (0..1) in actuator order; sizes must match
  // the robot's actuator count. Non-finite values are rejected (throws).
  void setCommand(RobotId r, std::span<const double> positions, std::span<const double> stiffness);
  // The same in single precision, as agents and the wire carry it.
  void setCommand(RobotId r, std::span<const float> positions, std::span<const float> stiffness);
  // Per actuator, with its own servo gains (a Booster robot's joint command):
  // tau = kp (position - q) + kd (velocity - qdot) + torque at full drive.
  // Every span has one entry per actuator; non-finite values or negative
  // gains are rejected (throws). Non-joint actuators are ignored.
  struct ServoCommand {
    std::span<const double> position, velocity, torque, kp, kd;
  };
  void setServoCommand(RobotId r, const ServoCommand& command);
  // One body joint by index (a mimic joint cannot be commanded: its master is).
  void setJointTarget(RobotId r, int joint, double target_rad, double stiffness);
  // A named pose of the robot model at one stiffness for every joint.
  void setPoseTarget(RobotId r, const std::string& pose_name, double stiffness);

  // --- time -----------------------------------------------------------------------
  // One physics step (dt); completes the sensor frames when a control
  // period ends.
  void step();
  void stepControlPeriod();  // control_period / dt physics steps
  uint64_t stepCount() const { return physics_->stepCount(); }
  double time() const { return static_cast<double>(stepCount()) * scenario_.physics.dt; }

  // --- state ------------------------------------------------------------------------
  Pose torsoPose(RobotId r) const;
  Pose linkPose(RobotId r, int link) const;
  double jointPosition(RobotId r, int joint) const;
  engine::RigidBodyState ballState() const;
  void setBallState(const engine::RigidBodyState& state);
  // Upright: torso origin above the robot's `fallen_torso_height` (its description's)
  // and tilted less than `max_tilt` (rad from the vertical).
  bool isStanding(RobotId r, double max_tilt = kFallenTilt) const;
  static constexpr double kFallenTilt = 0.785;  // rad: 45 degrees
  // The last robot touching the ball (any link), if any has yet.
  const std::optional<BallTouch>& lastBallTouch() const { return last_touch_; }
  // Teleports a robot upright onto the carpet at (x, y, yaw) in a named pose,
  // at rest, holding that pose (a referee placing or removing a robot).
  void placeRobot(RobotId r, double x, double y, double yaw, const std::string& posture = "stand");
  // Puts the robot's torso at `torso` (field frame) with its joints in `posture`, at rest
  // (e.g. lying on the ground for get-up trials; the caller keeps it clear of the ground).
  void placeRobot(RobotId r, const Pose& torso, const std::string& posture);
  // As a referee moves a robot: lifted and set down at rest with its torso at (x, y) facing
  // `yaw`, as it was: the same joint angles, servo targets, height and tilt, only carried
  // and turned about the vertical. One that is not upright on both feet (tilted more than
  // kUprightForMoving, below its fallen_torso_height, or a foot off the carpet: mid-step,
  // fallen, squatting in a get-up) is set down in the stand pose instead (placeRobot).
  void moveRobot(RobotId r, double x, double y, double yaw);
  static constexpr double kUprightForMoving = 0.35;  // rad from the vertical
  // How often robot r has been placed or moved (placeRobot, moveRobot): a command computed
  // from a frame before its last placement answers a robot that is no longer there.
  uint64_t placements(RobotId r) const { return placements_.at(r); }

  // The sensor frame of the last completed control period (stays the
  // initial one when the scenario turns sensors off).
  const SensorFrame& sensorFrame(RobotId r) const { return sensors_->frame(r); }
  // Chest button, head and hand touch sensors are inputs (set by a scenario
  // or a test); the foot bumpers come from contacts.
  void setTouch(RobotId r, Touch sensor, bool pressed) { sensors_->setTouch(r, sensor, pressed); }
  SensorSystem& sensors() { return *sensors_; }
  // The robots' link contacts after the last physics step (articulation id = RobotId).
  const std::vector<engine::LinkContact>& contacts() const { return contacts_; }

  WorldSnapshot snapshot() const;
  // 64-bit hash over the full dynamic state and the step count.
  uint64_t stateHash() const;

  engine::PhysicsWorld& physics() { return *physics_; }
  const engine::PhysicsWorld& physics() const { return *physics_; }

 private:
  template <typename T>
  void applyCommand(RobotId r, std::span<const T> positions, std::span<const T> stiffness);
  void holdJoints(RobotId r, const std::vector<double>& q, double stiffness);
  static Pose standingTorso(const robots::RobotModel& model, const std::vector<double>& q, double x,
                            double y, double yaw);
  Scenario scenario_;
  std::shared_ptr<const fields::FieldModel> field_;
  std::unique_ptr<engine::PhysicsWorld> physics_;
  std::vector<RobotInfo> robots_;
  std::vector<uint64_t> placements_;  // per robot
  engine::BodyId ball_ = 0;
  int steps_per_control_ = 1;
  std::unique_ptr<SensorSystem> sensors_;
  std::vector<engine::LinkContact> contacts_;  // this step's, shared by sensors and ball tracking
  std::optional<BallTouch> last_touch_;
  void initSensors();
};

}  // namespace simsoccer::world
