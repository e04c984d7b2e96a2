#include "simsoccer/world/world.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "simsoccer/engine/config.hpp"
#include "simsoccer/engine/random.hpp"
#include "simsoccer/engine/state_hash.hpp"

namespace simsoccer::world {

namespace {

[[noreturn]] void scenarioError(const Scenario& s, const std::string& key,
                                const std::string& reason) {
  throw engine::ConfigError(s.source_file.empty() ? "<scenario " + s.name + ">" : s.source_file,
                            key, reason);
}

std::string robotKey(size_t i, const char* field) {
  return "robots[" + std::to_string(i) + "]." + field;
}

// Robots whose torsos start closer than this overlap.
constexpr double kMinRobotSpacing = 0.2;  // m

}  // namespace

World World::fromFile(const std::filesystem::path& scenario_file) {
  return World(loadScenario(scenario_file));
}

World::World(const Scenario& scenario) : scenario_(scenario) {
  const PhysicsConfig& pc = scenario_.physics;
  if (!(pc.dt > 0.0)) scenarioError(scenario_, "physics.dt", "must be > 0");
  const double ratio = pc.control_period / pc.dt;
  if (!(ratio >= 1.0) || ratio > 1e6 || std::abs(ratio - std::round(ratio)) > 1e-9 * ratio)
    scenarioError(scenario_, "physics.control_period", "must be a whole multiple of dt");
  if (pc.solver_iterations < 1)
    scenarioError(scenario_, "physics.solver_iterations", "must be >= 1");
  if (pc.joint_sweeps < 1 || pc.joint_sweeps > 16)
    scenarioError(scenario_, "physics.joint_sweeps", "must be 1..16");
  if (!(pc.contact_warm_start >= 0.0 && pc.contact_warm_start <= 1.0))
    scenarioError(scenario_, "physics.contact_warm_start", "must be 0..1");
  if (pc.friction_directions != 1 && pc.friction_directions != 2)
    scenarioError(scenario_, "physics.friction_directions", "must be 1 or 2");
  steps_per_control_ = static_cast<int>(std::lround(ratio));

  field_ = std::make_shared<const fields::FieldModel>(fields::loadFieldModel(scenario_.field_file));
  engine::PhysicsSettings settings;
  settings.dt = pc.dt;
  settings.solver_iterations = pc.solver_iterations;
  settings.joint_sweeps = pc.joint_sweeps;
  settings.contact_warm_start = pc.contact_warm_start;
  settings.friction_directions = pc.friction_directions;
  settings.bullet_solver = pc.bullet_solver;
  settings.envelope_in_solver = pc.envelope_in_solver;
  settings.cull_ground_pairs = pc.cull_ground_pairs;
  settings.gravity = Vec3(0, 0, pc.gravity);
  settings.solver_threads = solverThreads(pc);
  physics_ = std::make_unique<engine::PhysicsWorld>(settings);
  // The field's ground plane and both goals.
  physics_->addGround(field_->carpet);
  for (int side : {-1, 1})
    for (const engine::Shape& s : field_->goalShapes(side))
      physics_->addStaticShape(s, field_->goal.material);

  // Ball.
  const fields::BallModel& bm = field_->ball;
  engine::Shape ball_shape;
  ball_shape.type = engine::ShapeType::Sphere;
  ball_shape.radius = bm.radius;
  Pose ball_pose = Pose::Identity();
  Vec3 bp = scenario_.ball_position;
  if (bp.z() < 0.0)
    bp.z() = bm.radius;  // not given: resting on the carpet
  else if (bp.z() < bm.radius)
    scenarioError(scenario_, "ball.position",
                  "the ball's centre must be at least its radius (" +
                      engine::formatNumber(bm.radius) + " m) above the carpet");
  if (!field_->onCarpet(bp.x(), bp.y()))
    scenarioError(scenario_, "ball.position", "outside the carpet");
  ball_pose.translation() = bp;
  ball_ = physics_->addRigidBody(ball_shape, bm.mass, bm.material, bm.linear_damping,
                                 bm.angular_damping, ball_pose);
  physics_->setRigidBodyState(ball_, {ball_pose, scenario_.ball_velocity, Vec3::Zero()});

  // Robots, in scenario order; each model file is loaded once and shared.
  std::map<std::string, std::shared_ptr<const robots::RobotModel>> models;
  std::map<std::pair<int, int>, size_t> numbers;
  engine::NormalSampler normal(scenario_.seed);
  std::vector<Vec3> placed;
  for (size_t i = 0; i < scenario_.robots.size(); ++i) {
    const RobotPlacement& p = scenario_.robots[i];
    if (auto [it, fresh] = numbers.emplace(std::pair{p.team, p.number}, i); !fresh)
      scenarioError(scenario_, robotKey(i, "number"),
                    "duplicate player number " + std::to_string(p.number) + " in team " +
                        std::to_string(p.team) + " (also robots[" + std::to_string(it->second) +
                        "])");
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.yaw))
      scenarioError(scenario_, robotKey(i, "pose"), "must be finite");
    if (!field_->onCarpet(p.x, p.y))
      scenarioError(scenario_, robotKey(i, "pose"),
                    "robot placed outside the field: (" + engine::formatNumber(p.x) + ", " +
                        engine::formatNumber(p.y) + ") is beyond the carpet (|x| <= " +
                        engine::formatNumber(field_->halfLength() + field_->border) + ", |y| <= " +
                        engine::formatNumber(field_->halfWidth() + field_->border) + ")");
    const std::string file =
        p.model_file.empty() ? scenario_.robot_model_file.string() : p.model_file;
    auto& model = models[file];
    if (!model) model = std::make_shared<const robots::RobotModel>(robots::loadRobotModel(file));
    if (!model->poses.count(p.posture))
      scenarioError(scenario_, robotKey(i, "posture"),
                    "robot model '" + model->name + "' has no pose '" + p.posture + "'");
    std::vector<double> q = model->pose(p.posture);
    const auto& joints = model->body->joints;
    double x = p.x, y = p.y, yaw = p.yaw;
    if (scenario_.noise.position > 0) {
      x += scenario_.noise.position * normal();
      y += scenario_.noise.position * normal();
    }
    if (scenario_.noise.yaw > 0) yaw += scenario_.noise.yaw * normal();
    if (scenario_.noise.joints > 0) {
      for (size_t j = 0; j < q.size(); ++j)
        if (joints[j].mimic_of < 0)
          q[j] = std::clamp(q[j] + scenario_.noise.joints * normal(), joints[j].lower,
                            joints[j].upper);
      model->body->applyMimic(q);
    }
    if (!field_->onCarpet(x, y))
      scenarioError(
          scenario_, robotKey(i, "pose"),
          "placement noise moved the robot off the carpet: lower placement_noise.position");
    for (size_t k = 0; k < placed.size(); ++k)
      if ((placed[k].head<2>() - Vec3(x, y, 0).head<2>()).norm() < kMinRobotSpacing)
        scenarioError(scenario_, robotKey(i, "pose"),
                      "overlaps robots[" + std::to_string(k) + "] (torsos closer than " +
                          engine::formatNumber(kMinRobotSpacing) + " m)");
    placed.emplace_back(x, y, 0.0);
    RobotInfo info;
    info.team = p.team;
    info.number = p.number;
    info.model = model;
    info.body = physics_->addArticulation(model->body, standingTorso(*model, q, x, y, yaw), q,
                                          static_cast<int>(i));
    robots_.push_back(info);
    placements_.push_back(0);
    holdJoints(static_cast<RobotId>(i), q, 1.0);  // until commanded otherwise
  }
  initSensors();
}

void World::initSensors() {
  std::vector<SensorSystem::RobotRef> refs;
  for (size_t i = 0; i < robots_.size(); ++i)
    refs.push_back({robots_[i].body, static_cast<int>(i), robots_[i].model.get()});
  sensors_ = std::make_unique<SensorSystem>(scenario_.sensors, *field_, std::move(refs), *physics_,
                                            ball_, scenario_.seed, scenario_.physics.control_period,
                                            scenario_.physics.dt);
}

void World::setCommand(RobotId r, std::span<const double> positions,
                       std::span<const double> stiffness) {
  applyCommand(r, positions, stiffness);
}

void World::setCommand(RobotId r, std::span<const float> positions,
                       std::span<const float> stiffness) {
  applyCommand(r, positions, stiffness);
}

template <typename T>
void World::applyCommand(RobotId r, std::span<const T> positions, std::span<const T> stiffness) {
  const RobotInfo& info = robots_.at(r);
  const auto& actuators = info.model->actuators;
  if (positions.size() != actuators.size() || stiffness.size() != actuators.size())
    throw std::invalid_argument("command for robot " + std::to_string(r) + " needs " +
                                std::to_string(actuators.size()) + " positions and stiffnesses");
  for (size_t i = 0; i < actuators.size(); ++i)
    if (!std::isfinite(positions[i]) || !std::isfinite(stiffness[i]))
      throw std::invalid_argument("command for robot " + std::to_string(r) +
                                  ": non-finite value for " + actuators[i].name);
  for (size_t i = 0; i < actuators.size(); ++i) {
    if (actuators[i].kind == robots::Actuator::Kind::Joint)
      physics_->setJointTarget(info.body, actuators[i].index, positions[i], stiffness[i]);
    else if (actuators[i].kind == robots::Actuator::Kind::Hand)
      sensors_->commandHand(r, static_cast<size_t>(actuators[i].index), positions[i], stiffness[i]);
  }
}

void World::setServoCommand(RobotId r, const ServoCommand& c) {
  const RobotInfo& info = robots_.at(r);
  const auto& actuators = info.model->actuators;
  const std::span<const double>* parts[5] = {&c.position, &c.velocity, &c.torque, &c.kp, &c.kd};
  for (const auto* part : parts)
    if (part->size() != actuators.size())
      throw std::invalid_argument("servo command for robot " + std::to_string(r) + " needs " +
                                  std::to_string(actuators.size()) + " entries per field");
  for (size_t i = 0; i < actuators.size(); ++i) {
    for (const auto* part : parts)
      if (!std::isfinite((*part)[i]))
        throw std::invalid_argument("servo command for robot " + std::to_string(r) +
                                    ": non-finite value for " + actuators[i].name);
    if (c.kp[i] < 0.0 || c.kd[i] < 0.0)
      throw std::invalid_argument("servo command for robot " + std::to_string(r) +
                                  ": negative gain for " + actuators[i].name);
  }
  for (size_t i = 0; i < actuators.size(); ++i)
    if (actuators[i].kind == robots::Actuator::Kind::Joint)
      physics_->setJointCommand(info.body, actuators[i].index, c.position[i], c.velocity[i],
                                c.torque[i], c.kp[i], c.kd[i]);
}

void World::setJointTarget(RobotId r, int joint, double target_rad, double stiffness) {
  physics_->setJointTarget(robots_.at(r).body, joint, target_rad, stiffness);
}

void World::setPoseTarget(RobotId r, const std::string& pose_name, double stiffness) {
  holdJoints(r, robots_.at(r).model->pose(pose_name), stiffness);
}

void World::holdJoints(RobotId r, const std::vector<double>& q, double stiffness) {
  const RobotInfo& info = robots_.at(r);
  const auto& joints = info.model->body->joints;
  for (size_t j = 0; j < joints.size(); ++j)
    if (joints[j].motor >= 0)
      physics_->setJointTarget(info.body, static_cast<int>(j), q[j], stiffness);
}

// Upright at (x, y) facing yaw, soles 1 mm above the carpet.
Pose World::standingTorso(const robots::RobotModel& model, const std::vector<double>& q, double x,
                          double y, double yaw) {
  Pose torso = Pose::Identity();
  torso.translation() = Vec3(x, y, model.soleDepth(q) + 0.001);
  torso.rotate(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
  return torso;
}

void World::step() {
  physics_->step();
  physics_->linkContacts(contacts_);
  for (const engine::LinkContact& c : contacts_)
    if (c.other_body == static_cast<int>(ball_) && c.articulation < robots_.size())
      last_touch_ = BallTouch{static_cast<RobotId>(c.articulation), c.link, physics_->stepCount()};
  if (!scenario_.sensors.enabled) return;
  sensors_->afterStep(*physics_, contacts_);
  if (stepCount() % static_cast<uint64_t>(steps_per_control_) == 0)
    sensors_->finishPeriod(*physics_, controlTick(), time());
}

void World::stepControlPeriod() {
  for (int i = 0; i < steps_per_control_; ++i) step();
}

Pose World::torsoPose(RobotId r) const {
  return physics_->linkPose(robots_.at(r).body, 0);
}
Pose World::linkPose(RobotId r, int link) const {
  return physics_->linkPose(robots_.at(r).body, link);
}
double World::jointPosition(RobotId r, int joint) const {
  return physics_->jointPosition(robots_.at(r).body, joint);
}
engine::RigidBodyState World::ballState() const {
  return physics_->rigidBodyState(ball_);
}
void World::setBallState(const engine::RigidBodyState& state) {
  physics_->setRigidBodyState(ball_, state);
}

void World::placeRobot(RobotId r, double x, double y, double yaw, const std::string& posture) {
  const robots::RobotModel& model = *robots_.at(r).model;
  placeRobot(r, standingTorso(model, model.pose(posture), x, y, yaw), posture);
}

void World::placeRobot(RobotId r, const Pose& torso, const std::string& posture) {
  const RobotInfo& info = robots_.at(r);
  const std::vector<double>& q = info.model->pose(posture);
  physics_->resetArticulation(info.body, torso, q);
  holdJoints(r, q, 1.0);
  sensors_->robotPlaced(*physics_, r);
  ++placements_.at(r);
}

void World::moveRobot(RobotId r, double x, double y, double yaw) {
  const RobotInfo& info = robots_.at(r);
  const robots::RobotModel& model = *info.model;
  // On both feet: each foot link touched the carpet in the last step.
  bool on_both_feet = model.hasLegs();
  for (const robots::LegChain& leg : model.legs) {
    const bool down = std::any_of(contacts_.begin(), contacts_.end(), [&](const auto& c) {
      return c.articulation == info.body && c.link == leg.foot_link && !c.with_articulation &&
             c.other_body < 0 && c.impulse > 0.0;
    });
    on_both_feet = on_both_feet && down;
  }
  if (!on_both_feet || !isStanding(r, kUprightForMoving)) {
    placeRobot(r, x, y, yaw);
    return;
  }
  const Pose torso = torsoPose(r);
  const double heading = std::atan2(torso.linear()(1, 0), torso.linear()(0, 0));
  Pose moved = Pose::Identity();
  moved.translation() = Vec3(x, y, torso.translation().z());
  moved.linear() =
      Eigen::AngleAxisd(yaw - heading, Vec3::UnitZ()).toRotationMatrix() * torso.linear();
  std::vector<double> q(model.body->joints.size());
  physics_->readJoints(info.body, q, {}, {}, {}, {});
  // The servos keep their targets: the robot's controller goes on from where it was.
  physics_->resetArticulation(info.body, moved, q);
  sensors_->robotPlaced(*physics_, r);
  ++placements_.at(r);
}

bool World::isStanding(RobotId r, double max_tilt) const {
  const double min_height = robots_.at(r).model->fallen_torso_height;
  const Pose torso = torsoPose(r);
  const double up_z = torso.linear()(2, 2);
  return torso.translation().z() > min_height && up_z > std::cos(max_tilt);
}

WorldSnapshot World::snapshot() const {
  WorldSnapshot s;
  s.step = stepCount();
  s.time = time();
  for (const RobotInfo& info : robots_) {
    RobotState rs;
    rs.torso = physics_->linkPose(info.body, 0);
    rs.linear_velocity = physics_->rootLinearVelocity(info.body);
    rs.angular_velocity = physics_->rootAngularVelocity(info.body);
    const int n = static_cast<int>(info.model->body->joints.size());
    for (int j = 0; j < n; ++j) {
      rs.joint_positions.push_back(physics_->jointPosition(info.body, j));
      rs.joint_velocities.push_back(physics_->jointVelocity(info.body, j));
    }
    s.robots.push_back(std::move(rs));
  }
  s.ball = ballState();
  return s;
}

uint64_t World::stateHash() const {
  std::vector<double> values;
  physics_->appendState(values);
  const uint64_t step = stepCount();
  return engine::hashValues(values, engine::hashBytes(&step, sizeof step));
}

}  // namespace simsoccer::world
