#include "simsoccer/world/sensor_system.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "simsoccer/engine/config.hpp"
#include "simsoccer/engine/fsr.hpp"

namespace simsoccer::world {

using engine::Pose;
using engine::Vec3;
using engine::Vec3f;

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kStandardGravity = 9.81;  // m/s^2, LoLA's kg = N / g
constexpr int32_t kGroundObject = 0;
constexpr int32_t kBallObject = 1;
constexpr int32_t kGoalObjectBase = 10;
constexpr int32_t kRobotObjectBase = 1000;
constexpr int32_t kBallOwner = -4, kGoalMinusOwner = -3, kGoalPlusOwner = -2;

const robots::SensorFrame& needSensor(const robots::RobotModel& model, const std::string& name) {
  const robots::SensorFrame* s = model.sensor(name);
  if (!s)
    throw engine::ConfigError(model.source_file, "sensors",
                              "missing sensor frame '" + name + "' (needed for the sensor frame)");
  return *s;
}

float clampAbs(double v, double range) {
  return static_cast<float>(std::clamp(v, -range, range));
}

// The encoder's step (rad), and a joint angle as the encoder reads it.
double encoderResolution(const robots::SensorSpec& spec) {
  return 2.0 * std::numbers::pi / static_cast<double>(1 << spec.encoder_bits);
}
float encoderReading(double q, double resolution) {
  return static_cast<float>(std::round(q / resolution) * resolution);
}

// The torso's roll, pitch and yaw (the IMU's angles) from its orientation.
std::array<double, 3> rollPitchYaw(const engine::Mat3& R) {
  return {std::atan2(R(2, 1), R(2, 2)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)),
          std::atan2(R(1, 0), R(0, 0))};
}

void addShape(engine::RayScene& scene, const engine::Shape& s, const Pose& world, int32_t object,
              int32_t owner, uint8_t cluster = 0) {
  const Pose p = world * s.pose;
  const Vec3f c = p.translation().cast<float>();
  const Vec3f axis = p.linear().col(2).cast<float>();
  switch (s.type) {
    case engine::ShapeType::Sphere:
      scene.addSphere(c, static_cast<float>(s.radius), object, owner, cluster);
      break;
    case engine::ShapeType::Capsule: {
      const float half = static_cast<float>(0.5 * s.length - s.radius);
      scene.addCapsule(c - half * axis, c + half * axis, static_cast<float>(s.radius), object,
                       owner, cluster);
      break;
    }
    case engine::ShapeType::Box:
      scene.addBox(c, p.linear().cast<float>(), (0.5 * s.extents).cast<float>(), object, owner,
                   cluster);
      break;
    case engine::ShapeType::Cylinder:
      scene.addCylinder(c, axis, static_cast<float>(0.5 * s.length), static_cast<float>(s.radius),
                        object, owner, cluster);
      break;
  }
}

// The furthest any point of a shape lies from the shape's own origin.
double shapeReach(const engine::Shape& s) {
  switch (s.type) {
    case engine::ShapeType::Sphere:
      return s.radius;
    case engine::ShapeType::Capsule:
      return 0.5 * s.length;  // end to end, caps included
    case engine::ShapeType::Box:
      return 0.5 * s.extents.norm();
    case engine::ShapeType::Cylinder:
      return std::hypot(0.5 * s.length, s.radius);
  }
  return 0.0;
}

// The furthest any collision shape of a body lies from its root link's frame,
// whatever its joint angles: a joint turns its child about the child frame's
// origin, so along each chain the joint offsets' lengths add up (the joints
// come in tree order, parents first).
double bodyReach(const engine::ArticulatedModel& body) {
  std::vector<double> to_link(body.links.size(), 0.0);
  for (const engine::Joint& j : body.joints)
    to_link[static_cast<size_t>(j.child_link)] =
        to_link[static_cast<size_t>(j.parent_link)] + j.origin.norm();
  double furthest = 0.0;
  for (size_t l = 0; l < body.links.size(); ++l)
    for (const engine::Shape& s : body.links[l].shapes)
      furthest = std::max(furthest, to_link[l] + s.pose.translation().norm() + shapeReach(s));
  return furthest;
}

}  // namespace

SensorSystem::SensorSystem(const SensorSettings& settings, const fields::FieldModel& field,
                           std::vector<RobotRef> robots, const engine::PhysicsWorld& physics,
                           engine::BodyId ball, uint64_t seed, double control_period, double dt)
    : settings_(settings), field_(field), dt_(dt), ball_(ball) {
  sonar_every_ = std::max(1, static_cast<int>(std::lround(settings.sonar_period / control_period)));
  // Cone directions: a Vogel spiral over the cone's solid angle, with the
  // first ray on the axis; the outermost ray lies just inside the cone.
  const int k = std::max(1, settings.sonar_rays);
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (const RobotRef& ref : robots) {
    const robots::RobotModel& model = *ref.model;
    // The frame's arrays hold up to kActuators entries (a Nao's 25 LoLA
    // slots); a robot with fewer leaves the rest 0.
    if (model.actuators.size() > kActuators)
      throw engine::ConfigError(model.source_file, "actuators",
                                "the sensor frame holds at most " + std::to_string(kActuators) +
                                    " actuators, the model has " +
                                    std::to_string(model.actuators.size()));
    Robot r;
    r.body = ref.body;
    r.group = ref.collision_group;
    r.model = ref.model;
    r.reach = bodyReach(*model.body);
    for (size_t a = 0; a < model.actuators.size(); ++a) {
      const auto& act = model.actuators[a];
      if (act.kind != robots::Actuator::Kind::Joint) continue;
      const auto j = static_cast<size_t>(act.index);
      const auto& motor = model.body->motors[static_cast<size_t>(model.body->joints[j].motor)];
      r.joint_motors.push_back({a, j, motor.torque_constant * motor.gear_ratio,
                                motor.no_load_current, motor.no_load_speed, motor.resistance,
                                motor.thermal_resistance,
                                motor.thermal_time_constant / motor.thermal_resistance});
    }
    // Sensors are what the model has: foot pressure sensors, toe bumpers and
    // sonars are a Nao's; a robot without them (a Booster K1) reports none.
    const char* feet[2] = {"L", "R"};
    const char* corners[4] = {"FL", "FR", "RL", "RR"};
    int fsrs_found = 0;
    for (const char* side : feet)
      for (const char* corner : corners)
        fsrs_found += model.sensor(std::string(side) + "Fsr" + corner) != nullptr;
    if (fsrs_found != 0 && fsrs_found != 8)
      throw engine::ConfigError(model.source_file, "sensors",
                                "foot pressure sensors come in eights (LFsrFL ... RFsrRR), found " +
                                    std::to_string(fsrs_found));
    r.has_feet = fsrs_found == 8;
    if (!r.has_feet)
      for (const char* side : feet)
        for (const char* which : {"FootBumperLeft", "FootBumperRight"})
          if (model.sensor(std::string(side) + which))
            throw engine::ConfigError(model.source_file, "sensors",
                                      std::string("a toe bumper (") + side + which +
                                          ") needs the foot's pressure sensors (its sole frame)");
    for (int f = 0; f < 2 && r.has_feet; ++f) {
      Foot& foot = r.feet[static_cast<size_t>(f)];
      for (int c = 0; c < 4; ++c) {
        const auto& s = needSensor(model, std::string(feet[f]) + "Fsr" + corners[c]);
        foot.link = s.link;
        foot.fsr[static_cast<size_t>(c)] = s.pose.translation();
      }
      foot.rect.x_front = 0.5 * (foot.fsr[0].x() + foot.fsr[1].x());
      foot.rect.x_rear = 0.5 * (foot.fsr[2].x() + foot.fsr[3].x());
      foot.rect.y_left = 0.5 * (foot.fsr[0].y() + foot.fsr[2].y());
      foot.rect.y_right = 0.5 * (foot.fsr[1].y() + foot.fsr[3].y());
      foot.sole_z = foot.fsr[0].z();
      const robots::SensorFrame* left = model.sensor(std::string(feet[f]) + "FootBumperLeft");
      const robots::SensorFrame* right = model.sensor(std::string(feet[f]) + "FootBumperRight");
      if ((left == nullptr) != (right == nullptr))
        throw engine::ConfigError(model.source_file, "sensors",
                                  std::string("toe bumpers come in pairs (") + feet[f] +
                                      "FootBumperLeft, " + feet[f] + "FootBumperRight)");
      foot.has_bumpers = left && right;
      if (foot.has_bumpers) {
        foot.bumper[0] = left->pose.translation();
        foot.bumper[1] = right->pose.translation();
      }
    }
    r.accel_point = needSensor(model, "Accelerometer").pose.translation();
    if (needSensor(model, "Accelerometer").link != 0)
      throw engine::ConfigError(model.source_file, "sensors",
                                "the accelerometer must be on the root link");
    const robots::SensorFrame* sonars[2] = {model.sensor("SonarLeft"), model.sensor("SonarRight")};
    if ((sonars[0] == nullptr) != (sonars[1] == nullptr))
      throw engine::ConfigError(model.source_file, "sensors",
                                "sonars come in pairs (SonarLeft, SonarRight)");
    r.has_sonars = sonars[0] != nullptr;
    for (size_t s = 0; s < 2 && r.has_sonars; ++s) {
      r.sonar_link[s] = sonars[s]->link;
      r.sonar_pose[s] = sonars[s]->pose;
    }
    const char* touch_names[kTouchSensors] = {
        "ChestButton",     "HeadTouchFront",   "HeadTouchMiddle",  "HeadTouchRear",
        "LFootBumperLeft", "LFootBumperRight", "LHandTouchBack",   "LHandTouchLeft",
        "LHandTouchRight", "RFootBumperLeft",  "RFootBumperRight", "RHandTouchBack",
        "RHandTouchLeft",  "RHandTouchRight"};
    for (size_t t = 0; t < kTouchSensors; ++t) {
      const std::string name = touch_names[t];
      if (name.find("FootBumper") != std::string::npos) {
        const bool present = r.has_feet && r.feet[name[0] == 'L' ? 0 : 1].has_bumpers;
        r.touch_source[t] =
            present ? (name[0] == 'L' ? 0 : 2) + (name.find("Right") != std::string::npos) : -2;
      } else {
        r.touch_source[t] = model.sensor(name) ? -1 : -2;
      }
    }
    // Clusters for the ray broadphase: the root, and one per subtree hanging
    // off it (head, each arm, each leg).
    const auto& links = model.body->links;
    r.link_cluster.assign(links.size(), 0);
    uint8_t next_cluster = 1;
    for (const auto& joint : model.body->joints) {
      const auto child = static_cast<size_t>(joint.child_link);
      r.link_cluster[child] = joint.parent_link == 0
                                  ? next_cluster++
                                  : r.link_cluster[static_cast<size_t>(joint.parent_link)];
    }
    r.temperature.fill(model.sensor_spec.ambient_temperature);
    restartDifferences(physics, r);
    r.noise = engine::NormalSampler(seed ^ (0x9E3779B97F4A7C15ull * (robots_.size() + 1)));
    // This robot's sonar cone (its model's angle) in the sonar frame.
    const double cone_half = 0.5 * model.sensor_spec.sonar_cone_angle;
    for (int i = 0; i < k; ++i) {
      const double theta = k == 1 ? 0.0 : cone_half * std::sqrt(i / (k - 0.5));
      const double phi = i * golden;
      r.ray_dirs.emplace_back(std::cos(theta), std::sin(theta) * std::cos(phi),
                              std::sin(theta) * std::sin(phi));
    }
    robots_.push_back(r);
  }
  rays_per_sonar_ = static_cast<size_t>(k);
  for (int side : {-1, 1})
    for (const engine::Shape& s : field.goalShapes(side)) {
      static_shapes_.push_back(s);
      static_owner_.push_back(side < 0 ? kGoalMinusOwner : kGoalPlusOwner);
    }
  for (size_t i = 0; i < robots_.size(); ++i) {
    const auto a = robots_[i].body;
    if (articulation_robot_.size() <= a) articulation_robot_.resize(a + 1, -1);
    articulation_robot_[a] = static_cast<int>(i);
  }
  frames_.resize(robots_.size());
  rays_.reserve(robots_.size() * 2 * rays_per_sonar_);
  hits_.resize(robots_.size() * 2 * rays_per_sonar_);
  echo_scratch_.reserve(rays_per_sonar_);
  updateSonar(physics);
}

void SensorSystem::setTouch(size_t robot, Touch sensor, bool pressed) {
  Robot& r = robots_.at(robot);
  const auto t = static_cast<size_t>(sensor);
  if (r.touch_source[t] != -1)
    throw std::invalid_argument("touch sensor " + std::to_string(t) +
                                " is not an input on this robot (a bumper, or absent)");
  r.touch_input[t] = pressed;
}

void SensorSystem::commandHand(size_t robot, size_t hand, double target, double stiffness) {
  Robot& r = robots_.at(robot);
  const auto& h = r.model->hands.at(hand);
  r.hand_target.at(hand) = std::clamp(target, h.lower, h.upper);
  r.hand_stiffness.at(hand) = std::clamp(stiffness, 0.0, 1.0);
}

void SensorSystem::restartDifferences(const engine::PhysicsWorld& physics, Robot& r) {
  for (size_t a = 0; a < r.model->actuators.size(); ++a) {
    const auto& act = r.model->actuators[a];
    if (act.kind == robots::Actuator::Kind::Joint)
      r.last_position[a] = physics.jointPosition(r.body, act.index);
  }
  const Pose torso = physics.linkPose(r.body, 0);
  r.last_accel_point_velocity = physics.rootPointVelocity(r.body, torso * r.accel_point);
}

void SensorSystem::robotPlaced(const engine::PhysicsWorld& physics, size_t robot) {
  Robot& r = robots_.at(robot);
  restartDifferences(physics, r);
  // The instantaneous readings of the robot as placed, at rest (no noise drawn: the
  // period's readings keep their sequence).
  SensorFrame& f = frames_.at(robot);
  const auto& spec = r.model->sensor_spec;
  const double resolution = encoderResolution(spec);
  for (const JointMotor& m : r.joint_motors) {
    f.position[m.actuator] = encoderReading(r.last_position[m.actuator], resolution);
    f.velocity[m.actuator] = 0.0f;
  }
  const engine::Mat3& R = physics.linkPose(r.body, 0).linear();
  const Vec3 accel = R.transpose() * -physics.settings().gravity;
  const std::array<double, 3> angles = rollPitchYaw(R);
  for (size_t k = 0; k < 3; ++k) {
    f.accelerometer[k] =
        clampAbs(accel[static_cast<int>(k)] + settings_.accel_bias[k], spec.accel_range);
    f.gyroscope[k] = clampAbs(settings_.gyro_bias[k], spec.gyro_range);
    f.angles[k] = static_cast<float>(angles[k]);
  }
}

void SensorSystem::afterStep(const engine::PhysicsWorld& physics,
                             const std::vector<engine::LinkContact>& contacts) {
  const auto t0 = timers_on_ ? Clock::now() : Clock::time_point{};
  ++steps_in_period_;

  // Feet: contact impulses on the soles (FSRs) and on the toes (bumpers).
  for (Robot& r : robots_) r.feet_posed = false;
  for (const engine::LinkContact& c : contacts) {
    if (c.articulation >= articulation_robot_.size()) continue;
    const int ri = articulation_robot_[c.articulation];
    if (ri < 0) continue;
    Robot& r = robots_[static_cast<size_t>(ri)];
    if (!r.has_feet) continue;
    const int f = c.link == r.feet[0].link ? 0 : c.link == r.feet[1].link ? 1 : -1;
    if (f < 0) continue;
    if (!r.feet_posed) {
      for (int k = 0; k < 2; ++k)
        r.foot_from_world[static_cast<size_t>(k)] =
            physics.linkPose(r.body, r.feet[static_cast<size_t>(k)].link).inverse(Eigen::Isometry);
      r.feet_posed = true;
    }
    const Foot& foot = r.feet[static_cast<size_t>(f)];
    const Pose& to_foot = r.foot_from_world[static_cast<size_t>(f)];
    const Vec3 p = to_foot * c.position;
    const Vec3 n = to_foot.linear() * c.normal;
    const double force = c.impulse / dt_;
    const double up = force * n.z();  // pressing on the sole
    if (up > 0.0 && p.z() < foot.sole_z + 0.01) {
      const auto w = engine::fsrWeights(foot.rect, p.x(), p.y());
      for (size_t k = 0; k < 4; ++k) r.fsr_sum[4 * static_cast<size_t>(f) + k] += up * w[k];
      r.weight_sum[static_cast<size_t>(f)] += up;
      r.cop_sum[static_cast<size_t>(f)] += up * p;
    }
    // A toe pushed against something: contact at the front, normal mostly horizontal.
    // (pushed backwards: the impulse on the foot points mostly along -x).
    if (foot.has_bumpers && force > 0.0 && -n.x() > 0.5 &&
        p.x() >= foot.bumper[0].x() - 0.005) {
      const double mid = 0.5 * (foot.bumper[0].y() + foot.bumper[1].y());
      r.bumper_hit[static_cast<size_t>(2 * f + (p.y() >= mid ? 0 : 1))] = true;
    }
  }

  for (Robot& r : robots_) {
    const Pose torso = physics.linkPose(r.body, 0);
    r.gyro_sum += torso.linear().transpose() * physics.rootAngularVelocity(r.body);
    const auto& model = *r.model;
    const size_t joints = model.body->joints.size();
    joint_velocity_.resize(joints);
    joint_motor_torque_.resize(joints);
    physics.readJoints(r.body, {}, joint_velocity_, joint_motor_torque_, {}, {});
    for (const JointMotor& m : r.joint_motors) {
      const double qd = std::abs(joint_velocity_[m.joint]);
      const double current = std::abs(joint_motor_torque_[m.joint]) / m.torque_per_amp +
                             m.no_load_current * std::min(1.0, qd / m.no_load_speed);
      r.current_sum[m.actuator] += current;
      r.current_sq_sum[m.actuator] += current * current;
    }
  }
  if (timers_on_) times_.other_s += std::chrono::duration<double>(Clock::now() - t0).count();
}

void SensorSystem::finishPeriod(const engine::PhysicsWorld& physics, uint64_t tick, double time) {
  const auto t0 = timers_on_ ? Clock::now() : Clock::time_point{};
  const int n = std::max(1, steps_in_period_);
  const double period = n * dt_;
  const Vec3 gravity = physics.settings().gravity;
  for (size_t ri = 0; ri < robots_.size(); ++ri) {
    Robot& r = robots_[ri];
    const auto& model = *r.model;
    const auto& spec = model.sensor_spec;
    SensorFrame& f = frames_[ri];
    f.tick = tick;
    f.time = time;

    // Joints and hands.
    const double resolution = encoderResolution(spec);
    const size_t joints = model.body->joints.size();
    joint_position_.resize(joints);
    joint_target_.resize(joints);
    joint_stiffness_.resize(joints);
    physics.readJoints(r.body, joint_position_, {}, {}, joint_target_, joint_stiffness_);
    for (const JointMotor& m : r.joint_motors) {
      const size_t a = m.actuator;
      const double q = joint_position_[m.joint];
      f.position[a] = encoderReading(q, resolution);
      f.velocity[a] = static_cast<float>((q - r.last_position[a]) / period);
      r.last_position[a] = q;
      f.target[a] = static_cast<float>(joint_target_[m.joint]);
      f.stiffness[a] = static_cast<float>(joint_stiffness_[m.joint]);
      f.current[a] = static_cast<float>(r.current_sum[a] / n);
      // Winding temperature: copper losses heat it, the housing cools it.
      const double power = m.resistance * r.current_sq_sum[a] / n;
      double& temp = r.temperature[a];
      temp += period * (power - (temp - spec.ambient_temperature) / m.thermal_resistance) /
              m.heat_capacity;
      f.temperature[a] = static_cast<float>(temp);
      f.status[a] = temp >= spec.temperature_critical   ? 3
                    : temp >= spec.temperature_very_hot ? 2
                    : temp >= spec.temperature_hot      ? 1
                                                        : 0;
    }
    for (size_t a = 0; a < model.actuators.size(); ++a) {
      const auto& act = model.actuators[a];
      if (act.kind == robots::Actuator::Kind::Hand) {
        const auto h = static_cast<size_t>(act.index);
        const double before = r.hand_position[h];
        const double reach = r.hand_stiffness[h] > 0.0 ? model.hands[h].speed * period : 0.0;
        r.hand_position[h] += std::clamp(r.hand_target[h] - before, -reach, reach);
        f.position[a] = static_cast<float>(r.hand_position[h]);
        f.velocity[a] = static_cast<float>((r.hand_position[h] - before) / period);
        f.target[a] = static_cast<float>(r.hand_target[h]);
        f.stiffness[a] = static_cast<float>(r.hand_stiffness[h]);
        f.temperature[a] = static_cast<float>(spec.ambient_temperature);
      }
      r.current_sum[a] = r.current_sq_sum[a] = 0.0;
    }

    // Inertial unit: specific force at the accelerometer from the change of
    // its velocity over the period; gyro averaged over the period.
    const Pose torso = physics.linkPose(r.body, 0);
    const engine::Mat3 rt = torso.linear().transpose();
    const Vec3 v = physics.rootPointVelocity(r.body, torso * r.accel_point);
    const Vec3 specific = (v - r.last_accel_point_velocity) / period - gravity;
    r.last_accel_point_velocity = v;
    const Vec3 accel = rt * specific;
    const Vec3 gyro = r.gyro_sum / n;
    r.gyro_sum.setZero();
    const std::array<double, 3> angles = rollPitchYaw(torso.linear());
    for (int k = 0; k < 3; ++k) {
      f.accelerometer[static_cast<size_t>(k)] =
          clampAbs(accel[k] + settings_.accel_bias[k] + settings_.accel_noise[k] * r.noise(),
                   spec.accel_range);
      f.gyroscope[static_cast<size_t>(k)] = clampAbs(
          gyro[k] + settings_.gyro_bias[k] + settings_.gyro_noise[k] * r.noise(), spec.gyro_range);
      f.angles[static_cast<size_t>(k)] =
          static_cast<float>(angles[static_cast<size_t>(k)] + settings_.angle_noise[k] * r.noise());
    }

    // Feet.
    for (size_t k = 0; k < kFsrs; ++k) {
      f.fsr[k] = static_cast<float>(r.fsr_sum[k] / n);
      f.fsr_kg[k] = static_cast<float>(r.fsr_sum[k] / n / kStandardGravity);
      r.fsr_sum[k] = 0.0;
    }
    for (size_t foot = 0; foot < 2; ++foot) {
      const double w = r.weight_sum[foot];
      f.foot_weight[foot] = static_cast<float>(w / n);
      f.centre_of_pressure[foot][0] = w > 1e-9 ? static_cast<float>(r.cop_sum[foot].x() / w) : 0.0f;
      f.centre_of_pressure[foot][1] = w > 1e-9 ? static_cast<float>(r.cop_sum[foot].y() / w) : 0.0f;
      r.weight_sum[foot] = 0.0;
      r.cop_sum[foot].setZero();
    }
    for (size_t t = 0; t < kTouchSensors; ++t) {
      const int src = r.touch_source[t];
      f.touch[t] = src >= 0    ? r.bumper_hit[static_cast<size_t>(src)]
                   : src == -1 ? r.touch_input[t]
                               : 0;
    }
    r.bumper_hit.fill(false);
  }
  steps_in_period_ = 0;
  ++times_.periods;
  if (timers_on_) times_.other_s += std::chrono::duration<double>(Clock::now() - t0).count();
  if (tick % static_cast<uint64_t>(sonar_every_) == 0) updateSonar(physics);
}

const std::vector<engine::Ray>& SensorSystem::buildSonarRays(const engine::PhysicsWorld& physics) {
  rays_.clear();
  for (size_t ri = 0; ri < robots_.size(); ++ri) {
    Robot& r = robots_[ri];
    r.first_ray = rays_.size();
    if (!r.has_sonars) continue;
    const float range = static_cast<float>(r.model->sensor_spec.sonar_max_range);
    for (size_t s = 0; s < 2; ++s) {
      const Pose sonar = physics.linkPose(r.body, r.sonar_link[s]) * r.sonar_pose[s];
      const Vec3f origin = sonar.translation().cast<float>();
      const engine::Mat3f rot = sonar.linear().cast<float>();
      for (const Vec3& d : r.ray_dirs) {
        engine::Ray ray;
        ray.origin = origin;
        ray.direction = (rot * d.cast<float>()).normalized();
        ray.max_distance = range;
        ray.exclude_owner = r.group;
        rays_.push_back(ray);
      }
    }
  }
  return rays_;
}

void SensorSystem::buildScene(const engine::PhysicsWorld& physics) {
  scene_.clear();
  scene_.setGround(kGroundObject);
  // Each goal and the ball is a broadphase group of its own (negative
  // owners: never excluded), so rays far from them skip them.
  const engine::RigidBodyState ball = physics.rigidBodyState(ball_);
  scene_.addSphere(ball.pose.translation().cast<float>(), static_cast<float>(field_.ball.radius),
                   kBallObject, kBallOwner);
  for (size_t i = 0; i < static_shapes_.size(); ++i)
    addShape(scene_, static_shapes_[i], Pose::Identity(), kGoalObjectBase + static_cast<int32_t>(i),
             static_owner_[i]);
  // Only robots a sonar of another robot can reach: their shapes are within
  // their reach of their root, the rays within their range of their origin.
  const size_t k = std::max<size_t>(1, rays_per_sonar_);
  for (const Robot& r : robots_) {
    const Vec3f root = physics.linkPose(r.body, 0).translation().cast<float>();
    bool reached = false;
    for (size_t i = 0; i < rays_.size() && !reached; i += k) {
      const engine::Ray& ray = rays_[i];
      const float within = ray.max_distance + static_cast<float>(r.reach) + 0.01f;
      reached =
          ray.exclude_owner != r.group && (ray.origin - root).squaredNorm() <= within * within;
    }
    if (!reached) continue;
    const auto& links = r.model->body->links;
    for (size_t l = 0; l < links.size(); ++l) {
      if (links[l].shapes.empty()) continue;
      const Pose pose = physics.linkPose(r.body, static_cast<int>(l));
      const int32_t object = kRobotObjectBase + r.group * 64 + static_cast<int32_t>(l);
      for (const engine::Shape& s : links[l].shapes)
        addShape(scene_, s, pose, object, r.group, r.link_cluster[l]);
    }
  }
  scene_.finalize();
}

void SensorSystem::traceBatched(const engine::PhysicsWorld& physics,
                                std::vector<engine::RayHit>& hits) {
  buildSonarRays(physics);
  buildScene(physics);
  hits.resize(rays_.size());
  scene_.trace(rays_, hits);
}

void SensorSystem::traceReference(const engine::PhysicsWorld& physics,
                                  std::vector<engine::RayHit>& hits) {
  buildSonarRays(physics);
  hits.resize(rays_.size());
  for (size_t i = 0; i < rays_.size(); ++i) {
    const engine::Ray& ray = rays_[i];
    const double d = physics.rayTestClosest(ray.origin.cast<double>(), ray.direction.cast<double>(),
                                            ray.max_distance, ray.exclude_owner);
    hits[i].distance = static_cast<float>(d);
    hits[i].object = std::isfinite(d) ? 0 : engine::kNoObject;
  }
}

void SensorSystem::updateSonar(const engine::PhysicsWorld& physics) {
  const auto t0 = timers_on_ ? Clock::now() : Clock::time_point{};
  traceBatched(physics, hits_);
  const size_t k = rays_per_sonar_;
  for (size_t ri = 0; ri < robots_.size(); ++ri) {
    if (!robots_[ri].has_sonars) continue;
    const auto& spec = robots_[ri].model->sensor_spec;
    const float min_cos = static_cast<float>(std::cos(spec.sonar_max_incidence));
    SensorFrame& f = frames_[ri];
    for (size_t s = 0; s < 2; ++s) {
      // One echo per object (a robot counts as one), the nearest ray that
      // returns from it; a ray returns only if it meets the surface within
      // the maximum incidence (smooth surfaces reflect ultrasound away).
      echo_scratch_.clear();
      for (size_t i = 0; i < k; ++i) {
        const size_t index = robots_[ri].first_ray + s * k + i;
        const engine::RayHit& h = hits_[index];
        if (h.object == engine::kNoObject) continue;
        if (-h.normal.dot(rays_[index].direction) < min_cos) continue;
        const int32_t echo_object = h.object >= kRobotObjectBase
                                        ? kRobotObjectBase + (h.object - kRobotObjectBase) / 64 * 64
                                        : h.object;
        echo_scratch_.emplace_back(h.distance, echo_object);
      }
      std::sort(echo_scratch_.begin(), echo_scratch_.end());
      size_t count = 0;
      auto& echoes = f.sonar_echoes[s];
      for (size_t i = 0;
           i < echo_scratch_.size() && count < static_cast<size_t>(spec.sonar_max_echoes); ++i) {
        bool seen = false;
        for (size_t j = 0; j < i; ++j)
          seen = seen || echo_scratch_[j].second == echo_scratch_[i].second;
        if (seen) continue;
        // Closer than the minimum range: the robot only knows something is there.
        echoes[count++] =
            std::max(echo_scratch_[i].first, static_cast<float>(spec.sonar_min_range));
      }
      for (size_t i = count; i < kSonarEchoes; ++i)
        echoes[i] = static_cast<float>(spec.sonar_no_echo_value);
      f.sonar_echo_count[s] = static_cast<uint8_t>(count);
      f.sonar[s] = echoes[0];
    }
  }
  ++times_.sonar_updates;
  if (timers_on_) times_.sonar_s += std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace simsoccer::world
