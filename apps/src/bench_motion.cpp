// simsoccer bench motion: the agents' motion (walk) on an empty field, in
// this process on the real physics, commands exactly as an agent sends them.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bench_scene.hpp"
#include "cli.hpp"
#include "simsoccer/agents/behaviour/soccer_behaviour.hpp"
#include "simsoccer/match/inprocess_agents.hpp"
#include "simsoccer/agents/motion/kick_engine.hpp"
#include "simsoccer/agents/motion/walk_engine.hpp"
#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "simsoccer/world/render_scene.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::apps {
namespace {

// The built-in agents in this process driving `world` through the period
// pipeline (the same stages, gate and actuation timing as a match).
struct AgentsInWorld {
  AgentsInWorld(world::World& world, std::vector<agents::Role> roles, uint64_t seed)
      : simulation(world, [] {
          sim::SimulationConfig c;
          c.mode = sim::kDefaultMode;
          return c;
        }()),
        agents(world, {std::move(roles), seed, true,
                       findConfig("", "configs/agents/soccer.yaml"),
                       findConfig("", "configs/motions")}) {
    simulation.addSource(agents);
  }
  void period() { simulation.period(); }
  const agents::MotionController& motion(world::RobotId r) const { return agents.motion(r); }
  const agents::SoccerBehaviour& behaviour(world::RobotId r) const { return agents.behaviour(r); }
  sim::Simulation simulation;
  match::InProcessAgents agents;
};

using engine::Vec3;

const char* kHelp =
    "usage: simsoccer bench motion [--random-minutes M] [--seed N] [--csv FILE]\n"
    "       simsoccer bench motion --vx V [--vy V] [--turn W] [--seconds S] [--verbose]\n"
    "\n"
    "One Nao on an empty SPL field, driven by the walk engine at the control rate through\n"
    "joint targets only (the agents' motion, in this process). Per test: commanded and achieved\n"
    "speed, path deviation, falls: forward 0.25 m/s over 5 m, sideways 0.1 m/s, turning 0.8\n"
    "rad/s, and M minutes (default 10) of random velocity commands.\n"
    "With --vx/--vy/--turn: one walk at that command; with --kick [--foot 0|1] [--ball-offset M] "
    "[--ball-gap M]:\n"
    "one kick; both for tuning, with any parameter of agents::WalkParameters / KickParameters\n"
    "by name (--sway, --lift, --period, --torso-offset, --height, --ankle-pitch-gyro,\n"
    "--ankle-roll-gyro, --lean, --hip-roll, --heading-gain, --kick-reach, --kick-swing,\n"
    "--kick-shift, --kick-lift, --kick-draw-back, --kick-hip-roll, --kick-swing-height).\n"
    "With --get-up front|back [--seed N] [--verbose]: one get-up trial.\n"
    "With --striker or --penalty [--seed N] [--verbose]: one striker / penalty trial.\n"
    "With --block [--shootout] [--seed N] [--verbose]: one ball rolled at the goalkeeper (in\n"
    "play: it blocks; in the shoot-out: it also dives).\n"
    "  --get-up-trials N, --sit-trials N  get-up trials per side, sit trials, in the table\n"
    "                (default 20, 20)\n"
    "  --motions DIR the motions from DIR (default configs/motions; for tuning them): all of\n"
    "                get_up_front, get_up_back, block, dive_left, dive_right, sit_down, stand_up\n"
    "  --snapshots F.png  with --get-up: the robot seen from its side every 0.2 s (the first\n"
    "                7.2 s), tiled\n"
    "  --striker-trials N, --penalty-trials N, --block-trials N  trials in the table (default\n"
    "                20, 50, 20)\n"
    "  --csv FILE    also write the table as CSV\n";

struct WalkResult {
  double distance = 0.0, speed = 0.0, lateral = 0.0, turned = 0.0;
  bool fell = false;
  double fell_at = -1.0;
};

world::Scenario emptyField() {
  world::Scenario s;
  s.name = "bench_motion";
  s.field_file = findConfig("", "fields/spl.yaml");
  s.robot_model_file = findConfig("", "robots/nao_v6_h25.yaml");
  s.ball_position = {4.0, 2.5, -1.0};
  world::RobotPlacement p;
  p.x = -3.0;
  s.robots.push_back(p);
  return s;
}

// Commands (vx, vy, omega) as a function of time since the walk began.
using Schedule = std::function<Eigen::Vector3d(double)>;

// Joint targets (body joint order) as the robot's commands, full stiffness
// (a mimic joint follows its master's command).
void send(world::World& w, const std::vector<double>& targets) {
  const auto& joints = w.robot(0).model->body->joints;
  for (size_t j = 0; j < targets.size(); ++j)
    if (joints[j].mimic_of < 0) w.setJointTarget(0, static_cast<int>(j), targets[j], 1.0);
}

// 1 s from the stand pose into the walk's stance (eased in, then held).
void settleIntoStance(world::World& w, agents::WalkEngine& engine, std::vector<double>& targets) {
  const std::vector<double>& stand = w.robot(0).model->pose("stand");
  const double dt = w.scenario().physics.control_period;
  for (int i = 0; i < 100; ++i) {
    engine.easeIn(stand, i * dt, targets);
    send(w, targets);
    w.stepControlPeriod();
  }
}

WalkResult walk(const Schedule& schedule, double seconds, bool verbose,
                const agents::WalkParameters& wp, int* falls = nullptr) {
  world::World w(emptyField());
  const auto& model = *w.robot(0).model;
  agents::WalkEngine engine(model, wp);
  std::vector<double> targets = model.pose("stand");
  const double dt = w.scenario().physics.control_period;
  settleIntoStance(w, engine, targets);
  const engine::Pose start = w.torsoPose(0);
  const Eigen::Vector3d first = schedule(0.0);
  const double vx = first.x(), vy = first.y();
  WalkResult r;
  const long periods = static_cast<long>(seconds / dt);
  for (long i = 0; i < periods; ++i) {
    const Eigen::Vector3d c = schedule(i * dt);
    engine.setVelocity(c.x(), c.y(), c.z());
    const auto& f = w.sensorFrame(0);
    engine.update(dt, Vec3(f.gyroscope[0], f.gyroscope[1], f.gyroscope[2]), f.angles[2], targets);
    send(w, targets);
    w.stepControlPeriod();
    if (!w.isStanding(0)) {
      r.fell = true;
      r.fell_at = i * dt;
      if (!falls) break;
      // Counting falls: put the robot back up where it fell and walk on.
      ++*falls;
      if (verbose) {
        const Eigen::Vector3d c = schedule(i * dt);
        std::fprintf(stderr, "fall at %.2f s, command %.2f %.2f %.2f (before: %.2f %.2f %.2f)\n",
                     i * dt, c.x(), c.y(), c.z(), schedule(std::max(0.0, i * dt - 2.0)).x(),
                     schedule(std::max(0.0, i * dt - 2.0)).y(),
                     schedule(std::max(0.0, i * dt - 2.0)).z());
      }
      const engine::Pose t = w.torsoPose(0);
      w.placeRobot(0, t.translation().x(), t.translation().y(),
                   std::atan2(t.linear()(1, 0), t.linear()(0, 0)));
      engine = agents::WalkEngine(model, wp);
      settleIntoStance(w, engine, targets);  // as at the start, then on
      continue;
    }
    if (verbose && i % 25 == 0) {  // a trace every 0.25 s, for tuning
      const Vec3 t = w.torsoPose(0).translation();
      std::fprintf(stderr, "t %.2f torso %.3f %.3f %.3f  odometry %.3f  feet %.1f / %.1f N\n",
                   i * dt, t.x(), t.y(), t.z(), engine.odometry().x, f.foot_weight[0],
                   f.foot_weight[1]);
    }
  }
  const engine::Pose end = w.torsoPose(0);
  const Vec3 d = start.linear().transpose() * (end.translation() - start.translation());
  r.distance = std::hypot(d.x(), d.y());
  r.speed = (vx != 0 || vy == 0 ? d.x() : d.y()) / seconds;
  r.lateral = vx != 0 || vy == 0 ? d.y() : d.x();
  const Eigen::Matrix3d rel = start.linear().transpose() * end.linear();
  r.turned = std::atan2(rel(1, 0), rel(0, 0));
  return r;
}

struct KickResult {
  double distance = 0.0, direction = 0.0;  // m, rad (field frame, 0 = the robot's heading)
  bool fell = false;
};

// For tuning a kick: while the kicking foot is near the ball, its speed along
// the kick (from `last_foot`, a control period ago), its height and its
// sole's lowest corner, and the ball's speed and spin; `start`: the ball's
// start.
void traceKick(const world::World& w, int foot_link, const Vec3& start, double dt, double t,
               Vec3& last_foot) {
  const auto foot_pose = w.linkPose(0, foot_link);
  const Vec3 foot = foot_pose.translation();
  const engine::RigidBodyState ball = w.ballState();
  if ((foot - ball.pose.translation()).norm() < 0.4 && t < 3.5) {
    double sole = 1e9;  // the bottom corners of the foot's collision box
    const auto& model = *w.robot(0).model;
    const engine::Shape& box = model.body->links[static_cast<size_t>(foot_link)].shapes.front();
    for (double cx : {-0.5, 0.5})
      for (double cy : {-0.5, 0.5})
        sole = std::min(sole,
                        (foot_pose * box.pose *
                         Vec3(cx * box.extents.x(), cy * box.extents.y(), -0.5 * box.extents.z()))
                            .z());
    std::fprintf(stderr,
                 "t %.2f foot x %+.3f z %.3f sole %.3f speed %+.2f m/s | ball x %+.3f speed %.2f "
                 "m/s spin %+.1f rad/s (rolling %+.1f)\n",
                 t, foot.x() - start.x(), foot.z(), sole, (foot.x() - last_foot.x()) / dt,
                 ball.pose.translation().x() - start.x(), ball.linear_velocity.norm(),
                 ball.angular_velocity.y(), ball.linear_velocity.x() / w.field().ball.radius);
  }
  last_foot = foot;
}

// One kick from the walk's stance with the ball in front of the kicking foot
// (offset sideways by `ball_offset`, `gap` ahead of the toe); the ball's
// travel after 6 s.
KickResult kick(agents::Leg foot, double ball_offset, uint64_t seed,
                const agents::WalkParameters& wp, const agents::KickParameters& kp,
                bool verbose = false, double gap = 0.015) {
  world::Scenario s = emptyField();
  s.seed = seed;
  world::World w(s);
  const auto& model = *w.robot(0).model;
  agents::WalkEngine walk(model, wp);
  agents::KickEngine engine(model, wp, kp);
  std::vector<double> targets = model.pose("stand");
  settleIntoStance(w, walk, targets);
  const char* link = foot == agents::Leg::Left ? "LFoot" : "RFoot";
  const Vec3 f = w.linkPose(0, model.body->linkIndex(link)).translation();
  engine::RigidBodyState b;
  b.pose.translation() = Vec3(f.x() + 0.1025 + w.field().ball.radius + gap, f.y() + ball_offset,
                              w.field().ball.radius);
  w.setBallState(b);
  const Vec3 start = b.pose.translation();
  engine.start(foot);
  KickResult r;
  const double dt = w.scenario().physics.control_period;
  const int foot_link = model.body->linkIndex(link);
  Vec3 last_foot = w.linkPose(0, foot_link).translation();  // for the trace
  for (int i = 0; i < static_cast<int>(std::lround(6.0 / dt)); ++i) {
    const auto& fr = w.sensorFrame(0);
    if (engine.active()) {
      engine.update(dt, Vec3(fr.gyroscope[0], fr.gyroscope[1], fr.gyroscope[2]), targets);
      send(w, targets);
    }
    w.stepControlPeriod();
    r.fell = r.fell || !w.isStanding(0);
    if (verbose) traceKick(w, foot_link, start, dt, (i + 1) * dt, last_foot);
  }
  const Vec3 d = w.ballState().pose.translation() - start;
  r.distance = std::hypot(d.x(), d.y());
  r.direction = std::atan2(d.y(), d.x());
  return r;
}

struct GetUpResult {
  bool success = false;
  double seconds = -1.0;  // from lying still on the ground to standing in the stance
  int attempts = 0;
};

// For tuning motions by hand: where the robot's centre of mass is over its
// ground contacts, and which joints lag their targets. Printed per line:
// the CoM height, each link on the ground with its contact's offset from the
// CoM along the robot's heading (x: the torso's x axis on the ground; a
// posture is statically stable when the CoM lies among the contacts), and
// every joint more than 0.1 rad from its target.
void traceSupport(const world::World& w, std::span<const float> targets) {
  const auto& model = *w.robot(0).model;
  const auto& links = model.body->links;
  std::vector<engine::Pose> frames;
  for (size_t l = 0; l < links.size(); ++l) frames.push_back(w.linkPose(0, static_cast<int>(l)));
  const Vec3 com = model.body->centreOfMass(frames);
  const engine::Pose t = w.torsoPose(0);
  // Heading: the torso's x axis, or when that is vertical (lying), its z axis.
  Vec3 ahead(t.linear()(0, 0), t.linear()(1, 0), 0.0);
  if (ahead.norm() < 0.5) ahead = Vec3(t.linear()(0, 2), t.linear()(1, 2), 0.0);
  ahead.normalize();
  const Vec3 left = Vec3::UnitZ().cross(ahead);
  std::fprintf(stderr, "    com z %.3f  ground:", com.z());
  // Per link on the ground: the span of its contacts ahead of the CoM, and their mean sideways.
  struct Span {
    double behind = 1e9, ahead = -1e9, sideways = 0.0;  // m
    int contacts = 0;
  };
  std::vector<int> order;  // links in the order they were first seen
  std::vector<Span> span(links.size());
  for (const engine::LinkContact& c : w.contacts()) {
    if (c.articulation != w.robot(0).body || c.with_articulation || c.other_body >= 0) continue;
    Span& sp = span[static_cast<size_t>(c.link)];
    if (sp.contacts++ == 0) order.push_back(c.link);
    const Vec3 d = c.position - com;
    sp.behind = std::min(sp.behind, d.dot(ahead));
    sp.ahead = std::max(sp.ahead, d.dot(ahead));
    sp.sideways += d.dot(left);
  }
  for (int l : order) {
    const Span& sp = span[static_cast<size_t>(l)];
    std::fprintf(stderr, " %s(%+.2f..%+.2f,%+.2f)", links[static_cast<size_t>(l)].name.c_str(),
                 sp.behind, sp.ahead, sp.sideways / sp.contacts);
  }
  std::fprintf(stderr, "\n    lag:");
  for (size_t a = 0; a < model.actuators.size() && a < targets.size(); ++a) {
    if (model.actuators[a].kind != robots::Actuator::Kind::Joint) continue;
    const int j = model.actuators[a].index;
    const double e = targets[a] - w.jointPosition(0, j);
    if (std::abs(e) > 0.1)
      std::fprintf(stderr, " %s %+.2f", model.body->joints[static_cast<size_t>(j)].name.c_str(), e);
  }
  std::fprintf(stderr, "\n");
}

// One get-up trial: the robot dropped on its front or back (seeded heading,
// spot and joint jitter), the motion controller (fall detector, get-up,
// stance) given 12 s with a "stand" request. Success: standing (world truth)
// in the controller's stance within the time.
GetUpResult getUp(bool front, uint64_t seed, const std::string& motions_dir, bool verbose,
                  const std::string& snapshots = "") {
  world::Scenario s = emptyField();
  s.seed = seed;
  world::World w(s);
  const auto& model = *w.robot(0).model;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double yaw = M_PI * u(rng);
  engine::Pose torso = engine::Pose::Identity();
  torso.linear() = (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) *
                    Eigen::AngleAxisd((front ? 1 : -1) * (M_PI / 2 + 0.1 * u(rng)), Vec3::UnitY()))
                       .toRotationMatrix();
  torso.translation() = Vec3(-3.0 + 0.5 * u(rng), 0.5 * u(rng), 0.16);
  w.placeRobot(0, torso, "stand");
  agents::MotionController motion = agents::loadMotionController(model, motions_dir);
  std::vector<float> position(25), stiffness(25);
  const auto& joints = model.body->joints;
  const double dt = w.scenario().physics.control_period;
  // Lying limp for 1 s first (as after a fall), then the controller takes over.
  for (int i = 0; i < 100; ++i) {
    for (size_t j = 0; j < joints.size(); ++j)
      if (joints[j].mimic_of < 0)
        w.setJointTarget(0, static_cast<int>(j), w.jointPosition(0, static_cast<int>(j)), 0.1);
    w.stepControlPeriod();
  }
  GetUpResult r;
  double standing_for = 0.0;
  // --snapshots: the robot from its side every 0.2 s from 0.2 s, tiled into one image.
  std::unique_ptr<engine::OffscreenRenderer> renderer;
  std::vector<cv::Mat> tiles;
  if (!snapshots.empty()) renderer = std::make_unique<engine::OffscreenRenderer>();
  const Vec3 side(-std::sin(yaw), std::cos(yaw), 0.0);
  for (int i = 0; i < 1200; ++i) {
    agents::MotionRequest stand;
    motion.update(dt, agents::motionSensors(w.sensorFrame(0)), stand, position, stiffness);
    w.setCommand(0, std::span<const float>(position), std::span<const float>(stiffness));
    w.stepControlPeriod();
    if (verbose && i % 10 == 0) {
      const engine::Pose t = w.torsoPose(0);
      // The torso's x axis (forward), z axis (up) and y axis (left), world z
      // components: forward > 0 leans back, up < 0 is upside down, left > 0
      // rolled onto the right side.
      std::fprintf(stderr, "t %.2f %-10s tilt %.2f torso z %.3f forward %.2f up %.2f left %.2f\n",
                   i * dt, agents::motionStateName(motion.state()), motion.tilt(),
                   t.translation().z(), t.linear()(2, 0), t.linear()(2, 2), t.linear()(2, 1));
      traceSupport(w, position);
    }
    if (renderer && i % 20 == 0 && i >= 20 && tiles.size() < 36) {
      const Vec3 c = w.torsoPose(0).translation();
      const Vec3 at(c.x(), c.y(), 0.2);
      const engine::RenderView view =
          engine::pinholeView(world::lookAtPose(at + 0.9 * side, at), 320, 240, 0.75, 0.57);
      std::vector<engine::DrawItem> scene;
      world::buildRenderScene(w, scene);
      renderer->render(scene, std::span<const engine::RenderView>(&view, 1));
      cv::Mat bgr;
      cv::cvtColor(renderer->image(0), bgr, cv::COLOR_RGBA2BGR);
      cv::putText(bgr, std::to_string(i * dt).substr(0, 4) + " " + motionStateName(motion.state()),
                  cv::Point(4, 14), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 255, 255), 1);
      tiles.push_back(bgr);
    }
    const bool stance = motion.state() == agents::MotionState::Stance;
    standing_for = stance && w.isStanding(0) ? standing_for + dt : 0.0;
    if (standing_for >= 1.0) {
      r.success = true;
      r.seconds = (i + 1) * dt - 1.0;
      break;
    }
  }
  r.attempts = motion.counters().get_ups + motion.counters().failed_get_ups;
  if (renderer && !tiles.empty()) {
    while (tiles.size() % 6) tiles.push_back(cv::Mat::zeros(tiles[0].size(), tiles[0].type()));
    std::vector<cv::Mat> rows;
    for (size_t k = 0; k < tiles.size(); k += 6) {
      cv::Mat row;
      cv::hconcat(std::vector<cv::Mat>(tiles.begin() + k, tiles.begin() + k + 6), row);
      rows.push_back(row);
    }
    cv::Mat all;
    cv::vconcat(rows, all);
    if (!cv::imwrite(snapshots, all)) throw std::runtime_error(snapshots + ": cannot write");
  }
  return r;
}

// One sit trial: the robot walks at a seeded velocity for 2 s, is asked to
// sit for 5 s (the walk stops first), then to stand for 5 s. Success: on its
// feet throughout (World::isStanding, as the referee counts it), the torso at
// least 5 cm lower when seated, and back in the stance afterwards.
struct SitResult {
  bool success = false;
  double seated_height = 0.0;  // m, the torso after 5 s of sitting
  double up_seconds = -1.0;    // from the stand request to the stance
  int falls = 0;
};

SitResult sitTrial(uint64_t seed, const std::string& motions_dir) {
  world::Scenario s = emptyField();
  s.seed = seed;
  world::World w(s);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  w.placeRobot(0, -3.0 + 0.5 * u(rng), 0.5 * u(rng), M_PI * u(rng));
  agents::MotionController motion = agents::loadMotionController(*w.robot(0).model, motions_dir);
  std::vector<float> position(25), stiffness(25);
  const double dt = w.scenario().physics.control_period;
  agents::MotionRequest request;
  request.kind = agents::MotionRequest::Kind::Walk;
  request.forward = 0.1 + 0.1 * u(rng);
  request.left = 0.05 * u(rng);
  request.turn = 0.3 * u(rng);
  bool on_feet = true;
  double standing_height = 0.0;
  SitResult r;
  for (int i = 0; i < 1200; ++i) {
    if (i == 200) {
      standing_height = w.torsoPose(0).translation().z();
      request = agents::MotionRequest{};
      request.kind = agents::MotionRequest::Kind::Sit;
    }
    if (i == 700) {
      r.seated_height = w.torsoPose(0).translation().z();
      request = agents::MotionRequest{};
    }
    motion.update(dt, agents::motionSensors(w.sensorFrame(0)), request, position, stiffness);
    w.setCommand(0, std::span<const float>(position), std::span<const float>(stiffness));
    w.stepControlPeriod();
    on_feet = on_feet && w.isStanding(0);
    if (i >= 700 && r.up_seconds < 0 && motion.state() == agents::MotionState::Stance)
      r.up_seconds = (i + 1 - 700) * dt;
  }
  r.falls = motion.counters().falls;
  r.success = on_feet && r.falls == 0 && r.seated_height < standing_height - 0.05 &&
              motion.counters().sits == 1 && r.up_seconds >= 0;
  return r;
}

// The ball in a goal: past the goal line between the posts (field frame),
// +1 / -1 for the goal at +x / -x, 0 none.
int goalScored(const world::World& w) {
  const Vec3 b = w.ballState().pose.translation();
  const auto& f = w.field();
  if (std::abs(b.y()) >= 0.5 * f.goal.inner_width || b.z() > f.goal.clear_height) return 0;
  if (b.x() > f.halfLength() + f.ball.radius) return 1;
  if (b.x() < -f.halfLength() - f.ball.radius) return -1;
  return 0;
}

struct StrikerResult {
  bool scored = false;
  double seconds = 0.0;
  int falls = 0;
};

// A striker alone (team 0, attacking +x): robot and ball at seeded random
// spots in the field; up to `limit` s to score.
StrikerResult strikerTrial(uint64_t seed, double limit, bool verbose) {
  world::Scenario s = emptyField();
  s.seed = seed;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const fields::FieldModel field = fields::loadFieldModel(s.field_file);
  const double hl = field.halfLength() - 0.5, hw = field.halfWidth() - 0.5;
  s.robots[0].x = hl * u(rng);
  s.robots[0].y = hw * u(rng);
  s.robots[0].yaw = M_PI * u(rng);
  double bx = 0, by = 0;
  do {
    bx = (hl - 0.5) * u(rng);
    by = hw * u(rng);
  } while (std::hypot(bx - s.robots[0].x, by - s.robots[0].y) < 0.6);
  s.ball_position = {bx, by, -1.0};
  world::World w(s);
  AgentsInWorld agents(w, {agents::Role::Striker}, seed);
  StrikerResult r;
  const double dt = w.scenario().physics.control_period;
  for (int i = 0; i < static_cast<int>(limit / dt); ++i) {
    agents.period();
    if (verbose && (i % 100 == 0 || (i < 150 && i % 10 == 0)))
      std::fprintf(stderr, "t %5.2f %-10s tilt %.2f %s\n", i * dt,
                   agents::motionStateName(agents.motion(0).state()), agents.motion(0).tilt(),
                   agents.behaviour(0).status().c_str());
    if (goalScored(w) == 1) {
      r.scored = true;
      r.seconds = (i + 1) * dt;
      break;
    }
  }
  r.falls = agents.motion(0).counters().falls;
  return r;
}

enum class PenaltyOutcome { Goal, Saved, Missed, Timeout };
constexpr std::array<const char*, 4> kPenaltyOutcomeNames{"goal", "saved", "missed", "timeout"};

// One penalty: kicker (team 0) behind the ball on the +x penalty mark,
// keeper (team 1) on that goal line; ends on a goal, the ball out or stopped
// after the kick, or after `limit` s.
PenaltyOutcome penaltyTrial(uint64_t seed, double limit, bool verbose) {
  world::Scenario s = emptyField();
  s.seed = seed;
  const fields::FieldModel f = fields::loadFieldModel(s.field_file);
  const double mark = f.halfLength() - f.penalty_mark_distance.value_or(1.3);
  s.robots[0].x = mark - 0.5;
  s.robots[0].y = 0.0;
  s.robots[0].yaw = 0.0;
  world::RobotPlacement keeper;
  keeper.team = 1;
  keeper.x = f.halfLength() - 0.05;
  keeper.yaw = M_PI;
  s.robots.push_back(keeper);
  s.ball_position = {mark, 0.0, -1.0};
  // Both robots see as in configs/scenarios/penalty.yaml: with the realistic
  // profile's noise, misses and false balls.
  s.perception.realistic = true;
  world::World w(s);
  AgentsInWorld agents(w, {agents::Role::PenaltyKicker, agents::Role::PenaltyGoalkeeper}, seed);
  const double dt = w.scenario().physics.control_period;
  bool kicked = false;
  double still = 0.0;
  for (int i = 0; i < static_cast<int>(limit / dt); ++i) {
    agents.period();
    if (verbose && i % 100 == 0)
      std::fprintf(stderr, "t %5.1f kicker %s | keeper %s\n", i * dt,
                   agents.behaviour(0).status().c_str(), agents.behaviour(1).status().c_str());
    const auto ball = w.ballState();
    if (goalScored(w) == 1) return PenaltyOutcome::Goal;
    const Vec3 b = ball.pose.translation();
    if (!kicked && std::hypot(b.x() - mark, b.y()) > 0.05) kicked = true;
    // The keeper down before the kick: a goal (the referee's shoot-out rule).
    if (!kicked && !w.isStanding(1)) return PenaltyOutcome::Goal;
    if (!kicked) continue;
    // Wholly over the goal line outside the goal, or over the touchline: missed.
    if (b.x() > f.halfLength() + f.ball.radius || std::abs(b.y()) > f.halfWidth())
      return PenaltyOutcome::Missed;
    still = ball.linear_velocity.norm() < 0.02 ? still + dt : 0.0;
    if (still > 0.5) {
      // Stopped in play: the keeper's (touched, or it came to rest before the line).
      const auto& touch = w.lastBallTouch();
      return touch && touch->robot == 1 ? PenaltyOutcome::Saved : PenaltyOutcome::Missed;
    }
  }
  return PenaltyOutcome::Timeout;
}

struct BlockResult {
  bool saved = false, in_reach = false;
  int blocks = 0, falls = 0;
};

// The goalkeeper behaviour on its line (team 0, own goal at -x) and a ball
// rolled at the goal from 2.5 m out (seeded: 1.6-2.4 m/s, at a point of the
// goal line inside the posts); 4 s to see whether it goes in. Saved: it did
// not, and the keeper touched it. In reach: aimed within the block's reach
// of the keeper's middle.
BlockResult blockTrial(uint64_t seed, bool shootout, bool verbose) {
  world::Scenario s = emptyField();
  s.seed = seed;
  const fields::FieldModel f = fields::loadFieldModel(s.field_file);
  const auto config = agents::loadBehaviourConfig(findConfig("", "configs/agents/soccer.yaml"));
  // Where the behaviour's keeper stands.
  const double line =
      -f.halfLength() + (shootout ? config.shootout_keeper_line : config.keeper_line);
  s.robots[0].x = line;
  s.robots[0].y = 0.0;
  s.robots[0].yaw = 0.0;
  s.ball_position = {line + 2.5, 0.0, -1.0};
  world::World w(s);
  AgentsInWorld agents(w, {shootout ? agents::Role::PenaltyGoalkeeper : agents::Role::Goalkeeper},
                         seed);
  const double dt = w.scenario().physics.control_period;
  for (int i = 0; i < 200; ++i) {  // 2 s to settle into the stance
    agents.period();
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double half_goal = 0.5 * f.goal.inner_width - f.ball.radius;
  const Vec3 from(line + 2.5, 0.6 * u(rng), f.ball.radius);
  const Vec3 to(-f.halfLength(), half_goal * u(rng), f.ball.radius);
  const double speed = 2.0 + 0.4 * u(rng);
  engine::RigidBodyState b;
  b.pose.translation() = from;
  b.linear_velocity = speed * (to - from).normalized();
  b.angular_velocity = Vec3::UnitZ().cross(b.linear_velocity) / f.ball.radius;  // rolling
  w.setBallState(b);
  BlockResult r;
  // Where the ball would pass the keeper's line, from the keeper's middle;
  // its reach: the behaviour's (block, or in the shoot-out dive).
  const double y_at = from.y() + (to.y() - from.y()) * (from.x() - line) / (from.x() - to.x());
  r.in_reach = std::abs(y_at - w.torsoPose(0).translation().y()) <
               (shootout ? config.dive_reach : config.block_reach);
  for (int i = 0; i < 400; ++i) {
    agents.period();
    if (verbose && i % 10 == 0)
      std::fprintf(stderr, "t %.2f %-10s ball %.2f %.2f torso z %.3f\n", i * dt,
                   agents::motionStateName(agents.motion(0).state()),
                   w.ballState().pose.translation().x(), w.ballState().pose.translation().y(),
                   w.torsoPose(0).translation().z());
    if (goalScored(w) == -1) break;
  }
  const auto& touch = w.lastBallTouch();
  r.saved = goalScored(w) == 0 && touch && touch->robot == 0;
  r.blocks = agents.motion(0).counters().blocks + agents.motion(0).counters().dives;
  r.falls = agents.motion(0).counters().falls;
  return r;
}

}  // namespace

int benchMotion(int argc, char** argv, int first) {
  // Tuning knobs: the walk's and the kick's parameters by name.
  agents::WalkParameters wp;
  agents::KickParameters kp;
  const std::vector<std::pair<std::string, double*>> knobs{
      {"sway", &wp.sway},
      {"lift", &wp.foot_lift},
      {"period", &wp.step_period},
      {"torso-offset", &wp.torso_offset},
      {"height", &wp.ankle_height},
      {"ankle-pitch-gyro", &wp.ankle_pitch_gyro},
      {"ankle-roll-gyro", &wp.ankle_roll_gyro},
      {"lean", &wp.torso_lean},
      {"hip-roll", &wp.hip_roll_compensation},
      {"heading-gain", &wp.heading_gain},
      {"kick-reach", &kp.reach},
      {"kick-swing", &kp.swing_time},
      {"kick-shift", &kp.shift},
      {"kick-lift", &kp.lift},
      {"kick-draw-back", &kp.draw_back},
      {"kick-hip-roll", &kp.hip_roll_compensation},
      {"kick-swing-height", &kp.swing_height}};
  std::vector<std::string> valued{"seconds",
                                  "csv",
                                  "vx",
                                  "vy",
                                  "turn",
                                  "random-minutes",
                                  "seed",
                                  "foot",
                                  "ball-offset",
                                  "ball-gap",
                                  "get-up",
                                  "get-up-trials",
                                  "sit-trials",
                                  "striker-trials",
                                  "penalty-trials",
                                  "motions",
                                  "snapshots",
                                  "block-trials"};
  for (const auto& k : knobs) valued.push_back(k.first);
  const Options opt(argc, argv, first,
                    {"help", "verbose", "kick", "striker", "penalty", "block", "shootout"}, valued);
  if (opt.help(kHelp)) return 0;
  opt.noPositional();
  for (const auto& [name, value] : knobs) *value = opt.number(name, *value);
  // Another motions folder (same file names) for tuning get-up motions.
  const std::string motions_dir =
      opt.has("motions") ? opt.get("motions", "") : findConfig("", "configs/motions").string();
  if (opt.has("get-up")) {  // one get-up, for tuning
    const std::string side = opt.get("get-up", "");
    if (side != "front" && side != "back") throw UsageError("--get-up must be front or back");
    const GetUpResult r = getUp(side == "front", static_cast<uint64_t>(opt.number("seed", 1)),
                                motions_dir, opt.flag("verbose"), opt.get("snapshots", ""));
    std::printf("get-up from the %s: %s in %.2f s, %d attempts\n", side.c_str(),
                r.success ? "standing" : "FAILED", r.seconds, r.attempts);
    return 0;
  }
  if (opt.flag("striker")) {  // one striker trial, for tuning
    const StrikerResult r =
        strikerTrial(static_cast<uint64_t>(opt.number("seed", 1)), 60.0, opt.flag("verbose"));
    std::printf("striker: %s in %.1f s, %d falls\n", r.scored ? "scored" : "no goal", r.seconds,
                r.falls);
    return 0;
  }
  if (opt.flag("block")) {  // one ball at the goalkeeper, for tuning
    const BlockResult r = blockTrial(static_cast<uint64_t>(opt.number("seed", 1)),
                                     opt.flag("shootout"), opt.flag("verbose"));
    std::printf("block: %s (%s), %d blocks/dives, %d falls\n", r.saved ? "saved" : "not saved",
                r.in_reach ? "in reach" : "out of reach", r.blocks, r.falls);
    return 0;
  }
  if (opt.flag("penalty")) {  // one penalty, for tuning
    const PenaltyOutcome o =
        penaltyTrial(static_cast<uint64_t>(opt.number("seed", 1)), 30.0, opt.flag("verbose"));
    std::printf("penalty: %s\n", kPenaltyOutcomeNames[static_cast<size_t>(o)]);
    return 0;
  }
  if (opt.flag("kick")) {  // one kick, for tuning
    const KickResult r = kick(opt.number("foot", 1) == 0 ? agents::Leg::Left : agents::Leg::Right,
                              opt.number("ball-offset", 0), 1, wp, kp, opt.flag("verbose"),
                              opt.number("ball-gap", 0.015));
    std::printf("ball %.3f m at %.1f deg, fell %d\n", r.distance, r.direction * 180 / M_PI, r.fell);
    return 0;
  }
  if (opt.has("vx") || opt.has("vy") || opt.has("turn")) {  // one walk, for tuning
    const Eigen::Vector3d c(opt.number("vx", 0), opt.number("vy", 0), opt.number("turn", 0));
    const WalkResult r =
        walk([&](double) { return c; }, opt.number("seconds", 10.0), opt.flag("verbose"), wp);
    std::printf(
        "distance %.3f m, speed %.3f m/s, lateral %.3f m, turned %.3f rad, fell %d at %.2f\n",
        r.distance, r.speed, r.lateral, r.turned, r.fell, r.fell_at);
    return 0;
  }
  const double random_minutes = opt.number("random-minutes", 10.0);
  const auto seed = static_cast<uint64_t>(opt.number("seed", 1));
  std::printf(
      "simsoccer bench motion: one Nao H25 on an empty SPL field, walk engine (%.0f ms steps), "
      "joint targets only\n",
      wp.step_period * 1e3);
  std::fflush(stdout);
  Table table;
  table.header = {"robots", "test",          "commanded", "achieved",
                  "unit",   "deviation_pct", "falls",     "sim_seconds"};
  auto row = [&](const std::string& test, double commanded, double achieved, const char* unit,
                 double deviation, int falls, double seconds) {
    table.rows.push_back({"1", test, fmt(commanded, 3), fmt(achieved, 3), unit, fmt(deviation, 1),
                          std::to_string(falls), fmt(seconds, 0)});
    std::fprintf(stderr, "  %s done\n", test.c_str());
  };
  {
    const double v = 0.25, seconds = 22.0;  // 5 m and more
    const WalkResult r = walk([&](double) { return Eigen::Vector3d(v, 0, 0); }, seconds, false, wp);
    row("walk_forward", v, r.speed, "m/s", 100.0 * std::abs(r.lateral) / std::max(r.distance, 1e-9),
        r.fell, seconds);
  }
  {
    const double v = 0.1, seconds = 10.0;
    const WalkResult r = walk([&](double) { return Eigen::Vector3d(0, v, 0); }, seconds, false, wp);
    row("walk_sideways", v, r.speed, "m/s",
        100.0 * std::abs(r.lateral) / std::max(r.distance, 1e-9), r.fell, seconds);
  }
  {
    const double w = 0.8, seconds = 5.0;  // 4 rad: less than a turn, so the angle is unambiguous
    const WalkResult r = walk([&](double) { return Eigen::Vector3d(0, 0, w); }, seconds, false, wp);
    double turned = r.turned;
    if (turned < 0) turned += 2 * M_PI;
    row("turn", w * 180 / M_PI, turned / seconds * 180 / M_PI, "deg/s",
        100.0 * std::abs(turned - w * seconds) / (w * seconds), r.fell, seconds);
  }
  {
    // 20 kicks, 10 with each foot, the ball up to 2 cm either side of the
    // foot's middle (seeded); a success: >= 3 m within 15 degrees of straight.
    std::mt19937_64 rng(seed + 100);
    double sum = 0, worst_angle = 0;
    int ok = 0, falls = 0;
    for (int i = 0; i < 20; ++i) {
      const double offset = -0.02 + 0.04 * static_cast<double>(rng() >> 11) * 0x1.0p-53;
      const KickResult k = kick(i % 2 ? agents::Leg::Left : agents::Leg::Right, offset,
                                seed + static_cast<uint64_t>(i), wp, kp);
      sum += k.distance;
      worst_angle = std::max(worst_angle, std::abs(k.direction));
      ok += k.distance >= 3.0 && std::abs(k.direction) <= 15 * M_PI / 180;
      falls += k.fell;
    }
    row("kick_distance", 3.0, sum / 20, "m", worst_angle * 180 / M_PI, falls, 20 * 9.0);
    row("kick_success", 0.9, ok / 20.0, "share", 0, falls, 20 * 9.0);
  }
  {
    // Get-up: N trials from each side (seeded heading, spot, tilt); success:
    // standing in the stance within 12 s of lying still.
    const int trials = static_cast<int>(opt.number("get-up-trials", 20));
    for (const bool front : {true, false}) {
      int ok = 0;
      double worst = 0.0;
      for (int i = 0; i < trials; ++i) {
        const GetUpResult g =
            getUp(front, seed + 200 + static_cast<uint64_t>(i), motions_dir, false);
        ok += g.success && g.seconds < 8.0;
        worst = std::max(worst, g.success ? g.seconds : 12.0);
      }
      row(front ? "get_up_front" : "get_up_back", 0.95, ok / std::max(1.0, double(trials)), "share",
          worst, 0, trials * 13.0);
    }
  }
  {
    // Sit down (after walking) and stand up again: N seeded trials.
    const int trials = static_cast<int>(opt.number("sit-trials", 20));
    int ok = 0, falls = 0;
    double slowest = 0.0, highest = 0.0;
    for (int i = 0; i < trials; ++i) {
      const SitResult t = sitTrial(seed + 250 + static_cast<uint64_t>(i), motions_dir);
      ok += t.success;
      falls += t.falls;
      slowest = std::max(slowest, t.up_seconds < 0 ? 5.0 : t.up_seconds);
      highest = std::max(highest, t.seated_height);
    }
    std::fprintf(stderr, "  sit: seated torso at most %.3f m, back in the stance within %.2f s\n",
                 highest, slowest);
    row("sit_and_stand", 0, ok / std::max(1.0, double(trials)), "share", slowest, falls,
        trials * 12.0);
  }
  {
    // The striker alone: N seeded trials from random spots, 60 s each to score.
    const int trials = static_cast<int>(opt.number("striker-trials", 20));
    int scored = 0, falls = 0;
    std::vector<double> times;
    for (int i = 0; i < trials; ++i) {
      const StrikerResult s = strikerTrial(seed + 300 + static_cast<uint64_t>(i), 60.0, false);
      scored += s.scored;
      falls += s.falls;
      if (s.scored) times.push_back(s.seconds);
    }
    std::sort(times.begin(), times.end());
    const double median = times.empty() ? 0.0 : times[times.size() / 2];
    row("striker_scores", 0.8, scored / std::max(1.0, double(trials)), "share", median, falls,
        trials * 60.0);
  }
  {
    // Penalty kicks against the behaviour goalkeeper: N seeded trials.
    const int trials = static_cast<int>(opt.number("penalty-trials", 50));
    std::array<int, kPenaltyOutcomeNames.size()> count{};
    for (int i = 0; i < trials; ++i)
      ++count[static_cast<size_t>(
          penaltyTrial(seed + 500 + static_cast<uint64_t>(i), 30.0, false))];
    std::fprintf(stderr, "  penalties:");
    for (size_t k = 0; k < count.size(); ++k)
      std::fprintf(stderr, " %d %s", count[k], kPenaltyOutcomeNames[k]);
    std::fprintf(stderr, "\n");
    const auto share = [&](PenaltyOutcome o) {
      return count[static_cast<size_t>(o)] / std::max(1.0, double(trials));
    };
    row("penalty_scoring", 0, share(PenaltyOutcome::Goal), "share",
        100.0 * share(PenaltyOutcome::Saved), 0, trials * 30.0);
  }
  {
    // The goalkeeper against balls rolled at its goal (seeded): in play (it
    // blocks) and in the shoot-out (it also dives); the share kept out.
    const int trials = static_cast<int>(opt.number("block-trials", 20));
    for (const bool shootout : {false, true}) {
      int saved = 0, in_reach = 0, saved_in_reach = 0, blocks = 0, falls = 0;
      for (int i = 0; i < trials; ++i) {
        const BlockResult b = blockTrial(seed + 700 + static_cast<uint64_t>(i), shootout, false);
        saved += b.saved;
        in_reach += b.in_reach;
        saved_in_reach += b.saved && b.in_reach;
        blocks += b.blocks;
        falls += b.falls;
      }
      std::fprintf(stderr, "  %s: %d blocks/dives, %d of %d balls within reach saved\n",
                   shootout ? "shoot-out keeper" : "keeper", blocks, saved_in_reach, in_reach);
      row(shootout ? "shootout_keeper_saves" : "keeper_saves", 0,
          saved / std::max(1.0, double(trials)), "share",
          100.0 * saved_in_reach / std::max(1, in_reach), falls, trials * 6.0);
    }
  }
  {
    // Random commands (seeded), a new one every 2 s: forward -0.1..0.3 m/s,
    // sideways -0.1..0.1 m/s, turn -0.8..0.8 rad/s, each with a 1 in 4 chance of 0.
    std::mt19937_64 rng(seed);
    std::vector<Eigen::Vector3d> commands;
    const double seconds = random_minutes * 60.0;
    for (int i = 0; i < static_cast<int>(seconds / 2.0) + 1; ++i) {
      std::uniform_real_distribution<double> u(0, 1);
      auto pick = [&](double lo, double hi) {
        return u(rng) < 0.25 ? 0.0 : lo + (hi - lo) * u(rng);
      };
      commands.emplace_back(pick(-0.1, 0.3), pick(-0.1, 0.1), pick(-0.8, 0.8));
    }
    int falls = 0;
    walk([&](double t) { return commands[static_cast<size_t>(t / 2.0)]; }, seconds,
         opt.flag("verbose"), wp, &falls);
    row("random_commands", 0, 0, "-", 0, falls, seconds);
  }
  table.finish(
      "walk_forward: 0.25 m/s for 22 s (over 5 m), achieved = torso displacement / time (the speed "
      "ramp included), deviation = sideways drift / distance; walk_sideways likewise at 0.1 m/s; "
      "turn: 0.8 rad/s for 5 s; kick_distance: mean ball travel of 20 kicks (10 per foot, the "
      "ball up to 2 cm sideways of the foot's middle), deviation = the largest angle off "
      "straight (deg); kick_success: share of kicks >= 3 m within 15 deg; get_up_front / "
      "get_up_back: share of trials (robot dropped on its front / back, seeded) standing in the "
      "stance within 8 s, deviation column = the slowest trial's seconds (12: failed); "
      "sit_and_stand: share of trials (2 s walking at a seeded velocity, 5 s sitting, 5 s "
      "standing) on its feet throughout with the torso >= 5 cm lower seated and back in the "
      "stance, deviation column = the slowest stand-up's seconds; "
      "striker_scores: share of trials (robot and ball at seeded random spots, the striker "
      "behaviour alone) that score within 60 s, deviation column = the median seconds to score; "
      "penalty_scoring: share of penalty kicks (kicker behaviour against the goalkeeper "
      "behaviour, seeded) that score, deviation column = % saved; keeper_saves / "
      "shootout_keeper_saves: share of balls rolled at the goal (seeded, 1.6-2.4 m/s from 2.5 m, "
      "aimed inside the posts) the goalkeeper behaviour keeps out in play (it blocks) / in the "
      "shoot-out (it also dives), deviation column = % of those aimed within its reach "
      "(block_reach / dive_reach of configs/agents/soccer.yaml from its middle), falls = falls "
      "besides dives; "
      "random_commands: a new "
      "random velocity every 2 s on an empty field, falls counted (the robot is put back up "
      "after each).",
      opt.get("csv", ""));
  return 0;
}

}  // namespace simsoccer::apps
