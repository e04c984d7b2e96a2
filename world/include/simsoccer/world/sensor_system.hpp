// Produces every robot's SensorFrame from the physics: accumulates per
// physics step (foot contact forces, gyro, motor currents), completes the
// frame at the end of each control period (IMU, joints, temperatures) and
// traces all sonar rays of all robots in one batch every sonar period.
//
// The per-step and per-period work uses buffers sized at construction: no
// heap allocation once the first sonar update has sized the ray scene.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "simsoccer/engine/fsr.hpp"
#include "simsoccer/engine/physics_world.hpp"
#include "simsoccer/engine/random.hpp"
#include "simsoccer/engine/ray_tracer.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/robots/robot_model.hpp"
#include "simsoccer/world/scenario.hpp"
#include "simsoccer/world/sensor_frame.hpp"

namespace simsoccer::world {

struct SensorTimes {
  double sonar_s = 0.0;  // batched sonar updates (scene build + trace + echoes)
  double other_s = 0.0;  // every other sensor: per-step accumulation and per-period frames
  uint64_t sonar_updates = 0;
  uint64_t periods = 0;
};

class SensorSystem {
 public:
  struct RobotRef {
    engine::ArticulationId body;
    int collision_group;  // the robot's group in the physics world (ray exclusion)
    const robots::RobotModel* model;
  };
  SensorSystem(const SensorSettings& settings, const fields::FieldModel& field,
               std::vector<RobotRef> robots, const engine::PhysicsWorld& physics,
               engine::BodyId ball, uint64_t seed, double control_period, double dt);

  // After every physics step, with that step's link contacts.
  void afterStep(const engine::PhysicsWorld& physics,
                 const std::vector<engine::LinkContact>& contacts);
  // At the end of every control period.
  void finishPeriod(const engine::PhysicsWorld& physics, uint64_t tick, double time);
  // A robot put somewhere else (World::placeRobot): the next period's joint
  // velocities and accelerometer start from there, not from a jump of metres
  // and radians in one period (the referee's hands are not that fast). Its
  // frame describes it as placed (encoders, IMU angles, at rest), not as it was
  // before: a referee places robots after the step, and the frame the agents
  // read next would otherwise show the robot where it was (an agent restarted
  // by the GameState's Set eased from a get-up's pose that no longer was).
  void robotPlaced(const engine::PhysicsWorld& physics, size_t robot);

  const SensorFrame& frame(size_t robot) const { return frames_.at(robot); }
  void setTouch(size_t robot, Touch sensor, bool pressed);
  // Hands (actuators without a hinge): target and stiffness from commands.
  void commandHand(size_t robot, size_t hand, double target, double stiffness);

  // All sonar rays of all robots for the current poses (for tests and the
  // benchmark): rays[i] and, traced, hits[i].
  const std::vector<engine::Ray>& buildSonarRays(const engine::PhysicsWorld& physics);
  void traceBatched(const engine::PhysicsWorld& physics, std::vector<engine::RayHit>& hits);
  // The same rays one at a time through Bullet's rayTest (reference path).
  void traceReference(const engine::PhysicsWorld& physics, std::vector<engine::RayHit>& hits);

  void enableTimers(bool on) { timers_on_ = on; }
  const SensorTimes& times() const { return times_; }
  // The scene of the last sonar trace: the ball, the goals and the robots a
  // sonar of another robot could reach.
  const engine::RayScene& sonarScene() const { return scene_; }
  void resetTimes() { times_ = {}; }

 private:
  struct Foot {
    int link = -1;
    std::array<engine::Vec3, 4> fsr;  // FL, FR, RL, RR in the foot's joint frame
    engine::FsrRectangle rect;
    double sole_z = 0;
    std::array<engine::Vec3, 2> bumper;  // left, right
    bool has_bumpers = false;
  };
  // A joint actuator's motor constants, flat (the per-period loops read these,
  // not the model's joints and motors).
  struct JointMotor {
    size_t actuator = 0;                                                // index in the sensor frame
    size_t joint = 0;                                                   // index in the articulation
    double torque_per_amp = 0, no_load_current = 0, no_load_speed = 0;  // N m/A, A, rad/s
    double resistance = 0, thermal_resistance = 0, heat_capacity = 0;   // ohm, K/W, J/K
  };
  struct Robot {
    engine::ArticulationId body;
    int group = 0;
    const robots::RobotModel* model;
    std::vector<JointMotor> joint_motors;  // the model's joint actuators, in order
    double reach = 0;  // m: no collision shape lies further from the root link's frame
    std::vector<uint8_t> link_cluster;            // broadphase cluster: torso 0, each limb its own
    std::vector<engine::Vec3> ray_dirs;           // sonar cone directions, sonar frame (x = axis)
    std::array<engine::Pose, 2> foot_from_world;  // this step's, computed on first use
    bool feet_posed = false;
    bool has_feet = false;    // foot pressure sensors (a Nao's eight FSRs)
    bool has_sonars = false;  // a left and a right sonar
    size_t first_ray = 0;     // this robot's first sonar ray in rays_
    std::array<Foot, 2> feet;
    engine::Vec3 accel_point = engine::Vec3::Zero();  // torso frame
    std::array<int, 2> sonar_link{};
    std::array<engine::Pose, 2> sonar_pose;         // in the link frame
    std::array<int, kTouchSensors> touch_source{};  // -1: input, -2: absent, else bumper idx
    // Per-period accumulators.
    std::array<double, kFsrs> fsr_sum{};
    std::array<double, 2> weight_sum{};
    std::array<engine::Vec3, 2> cop_sum{};
    std::array<bool, 4> bumper_hit{};
    engine::Vec3 gyro_sum = engine::Vec3::Zero();
    std::array<double, kActuators> current_sum{}, current_sq_sum{};
    // Carried between periods.
    engine::Vec3 last_accel_point_velocity = engine::Vec3::Zero();
    std::array<double, kActuators> last_position{};
    std::array<double, kActuators> temperature{};
    std::array<double, 2> hand_position{}, hand_target{}, hand_stiffness{};
    std::array<bool, kTouchSensors> touch_input{};
    engine::NormalSampler noise{0};
  };

  void updateSonar(const engine::PhysicsWorld& physics);
  void restartDifferences(const engine::PhysicsWorld& physics, Robot& r);
  // The scene the sonar rays (rays_, built first) are traced against.
  void buildScene(const engine::PhysicsWorld& physics);

  SensorSettings settings_;
  const fields::FieldModel& field_;
  double dt_;
  int sonar_every_ = 6;  // control periods per sonar update
  engine::BodyId ball_;
  std::vector<Robot> robots_;
  std::vector<int> articulation_robot_;       // articulation id -> robot index (-1 none)
  std::vector<engine::Shape> static_shapes_;  // goals, field frame
  std::vector<int32_t> static_owner_;         // their broadphase group
  std::vector<SensorFrame> frames_;
  // One robot's joints as read from the physics (joint order), reused robot after robot.
  std::vector<double> joint_position_, joint_velocity_, joint_motor_torque_, joint_target_,
      joint_stiffness_;
  size_t rays_per_sonar_ = 0;
  int steps_in_period_ = 0;

  engine::RayScene scene_;
  std::vector<engine::Ray> rays_;
  std::vector<engine::RayHit> hits_;
  std::vector<std::pair<float, int32_t>> echo_scratch_;

  bool timers_on_ = false;
  SensorTimes times_;
};

}  // namespace simsoccer::world
