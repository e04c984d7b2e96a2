// simsoccer bench motion: the agents' motion (walk) on an empty field, in
// this process on the real physics, commands exactly as an agent sends them.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_scene.hpp"
#include "cli.hpp"
#include "simsoccer/agents/motion/walk_engine.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::apps {
namespace {

using engine::Vec3;

const char* kHelp =
    "usage: simsoccer bench motion [--seconds S] [--csv FILE]\n"
    "\n"
    "One Nao on an empty SPL field, driven by the walk engine at the control rate through\n"
    "joint targets only. Per test (forward, sideways, turning): commanded and achieved speed,\n"
    "path deviation, falls.\n"
    "  --seconds S   walking time per test (default 10)\n"
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

WalkResult walk(double vx, double vy, double omega, double seconds, bool verbose,
               const agents::WalkParameters& wp) {
  world::World w(emptyField());
  const auto& model = *w.robot(0).model;
  agents::WalkEngine engine(model, wp);
  std::vector<double> targets = model.pose("stand");
  std::vector<double> stiffness(targets.size(), 1.0);
  const double dt = w.scenario().physics.control_period;
  auto send = [&] {
    for (size_t j = 0; j < targets.size(); ++j)
      if (model.body->joints[j].mimic_of < 0) w.setJointTarget(0, static_cast<int>(j), targets[j], 1.0);
  };
  // Settle into the walk's stance over 1 s.
  const std::vector<double> stand = targets;
  std::vector<double> walk_stance = targets;
  engine.update(dt, Vec3::Zero(), 0.0, walk_stance);
  for (int i = 0; i < 100; ++i) {
    const double a = std::min(1.0, i / 50.0);
    for (size_t j = 0; j < targets.size(); ++j) targets[j] = (1 - a) * stand[j] + a * walk_stance[j];
    send();
    w.stepControlPeriod();
  }
  const engine::Pose start = w.torsoPose(0);
  engine.setVelocity(vx, vy, omega);
  WalkResult r;
  const long periods = static_cast<long>(seconds / dt);
  for (long i = 0; i < periods; ++i) {
    const auto& f = w.sensorFrame(0);
    engine.update(dt, Vec3(f.gyroscope[0], f.gyroscope[1], f.gyroscope[2]), f.angles[2], targets);
    send();
    w.stepControlPeriod();
    if (!w.isStanding(0)) {
      r.fell = true;
      r.fell_at = i * dt;
      break;
    }
    if (verbose && (i < 60 || i % 25 == 0)) {
      const auto t = w.torsoPose(0);
      const int hr = model.body->jointIndex("RHipRoll"), lk = model.body->jointIndex("LKneePitch");
      std::fprintf(stderr, "   RHipRoll cmd %.3f act %.3f  LKnee cmd %.3f act %.3f\n", targets[hr],
                   w.jointPosition(0, hr), targets[lk], w.jointPosition(0, lk));
      const auto lf = w.linkPose(0, model.body->linkIndex("LFoot")).translation();
      const auto rf = w.linkPose(0, model.body->linkIndex("RFoot")).translation();
      std::fprintf(stderr, "t %.2f ph %.2f sup %d torso %.3f %.3f %.3f  odo %.3f  weight L %.1f R %.1f  LF %.3f %.3f RF %.3f %.3f\n",
                   i * dt, engine.phase(), static_cast<int>(engine.supportLeg()), t.translation().x(),
                   t.translation().y(), t.translation().z(), engine.odometry().x,
                   f.foot_weight[0], f.foot_weight[1], lf.x(), lf.z(), rf.x(), rf.z());
    }
  }
  const engine::Pose end = w.torsoPose(0);
  const Vec3 d = start.linear().transpose() * (end.translation() - start.translation());
  r.distance = std::hypot(d.x(), d.y());
  r.speed = (vx != 0 ? d.x() : d.y()) / seconds;
  r.lateral = vx != 0 ? d.y() : d.x();
  const Eigen::Matrix3d rel = start.linear().transpose() * end.linear();
  r.turned = std::atan2(rel(1, 0), rel(0, 0));
  return r;
}

}  // namespace

int benchMotion(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "verbose"}, {"seconds", "csv", "vx", "vy", "turn", "sway", "lift", "period", "offset", "height", "gp", "gr", "lean", "hrc", "hg"});
  if (opt.help(kHelp)) return 0;
  opt.noPositional();
  const double seconds = opt.number("seconds", 10.0);
  if (opt.has("vx") || opt.has("vy") || opt.has("turn")) {
    agents::WalkParameters wp;
    wp.sway = opt.number("sway", wp.sway);
    wp.foot_lift = opt.number("lift", wp.foot_lift);
    wp.step_period = opt.number("period", wp.step_period);
    wp.torso_offset = opt.number("offset", wp.torso_offset);
    wp.ankle_height = opt.number("height", wp.ankle_height);
    wp.ankle_pitch_gyro = opt.number("gp", wp.ankle_pitch_gyro);
    wp.ankle_roll_gyro = opt.number("gr", wp.ankle_roll_gyro);
    wp.torso_lean = opt.number("lean", wp.torso_lean);
    wp.hip_roll_compensation = opt.number("hrc", wp.hip_roll_compensation);
    wp.heading_gain = opt.number("hg", wp.heading_gain);
    const WalkResult r = walk(opt.number("vx", 0), opt.number("vy", 0), opt.number("turn", 0),
                              seconds, opt.flag("verbose"), wp);
    std::printf("distance %.3f m, speed %.3f m/s, lateral %.3f m, turned %.3f rad, fell %d at %.2f\n",
                r.distance, r.speed, r.lateral, r.turned, r.fell, r.fell_at);
    return 0;
  }
  return 0;
}

}  // namespace simsoccer::apps
