// Getting up: the robot dropped on its front or back (seeded heading, spot
// and joint jitter), lying limp for 1 s, then the motion controller (fall
// detector, get-up, stance) with a "stand" request.
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "simsoccer/agents/motion/motion_controller.hpp"
#include "simsoccer/engine/offscreen_renderer.hpp"
#include "simsoccer/world/render_scene.hpp"
#include "trial.hpp"

namespace simsoccer::apps::motion {
namespace {

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

// The robot seen from its side, every tile one image, six to a row.
void writeTiles(std::vector<cv::Mat>& tiles, const std::string& file) {
  while (tiles.size() % 6) tiles.push_back(cv::Mat::zeros(tiles[0].size(), tiles[0].type()));
  std::vector<cv::Mat> rows;
  for (size_t k = 0; k < tiles.size(); k += 6) {
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>(tiles.begin() + k, tiles.begin() + k + 6), row);
    rows.push_back(row);
  }
  cv::Mat all;
  cv::vconcat(rows, all);
  if (!cv::imwrite(file, all)) throw std::runtime_error(file + ": cannot write");
}

}  // namespace

// Success: standing (world truth) in the controller's stance for 1 s within 12 s.
GetUpResult getUpTrial(const TrialContext& c, bool front, uint64_t seed,
                       const std::string& snapshots) {
  world::Scenario s = emptyField(c);
  s.seed = seed;
  TrialWorld t(s, c);
  world::World& w = t.world;
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
  agents::MotionController motion = agents::loadMotionController(model, c.motions_dir);
  const double dt = t.dt();
  // Lying limp for 1 s first (as after a fall): today's angles at stiffness 0.1.
  std::vector<double> q(model.body->joints.size());
  t.driver.setControl([&](const world::World& world, std::span<float> p, std::span<float> k) {
    for (size_t j = 0; j < q.size(); ++j) q[j] = world.jointPosition(0, static_cast<int>(j));
    bodyTargetsToCommand(model, q, 0.1, p, k);
    return true;
  });
  for (int i = 0; i < 100; ++i) t.period();
  // Then the controller takes over.
  std::vector<float> position(world::kActuators), stiffness(world::kActuators);
  t.driver.setControl([&](const world::World& world, std::span<float> p, std::span<float> k) {
    agents::MotionRequest stand;
    motion.update(dt, agents::motionSensors(world.sensorFrame(0)), stand, position, stiffness);
    std::copy(position.begin(), position.end(), p.begin());
    std::copy(stiffness.begin(), stiffness.end(), k.begin());
    return true;
  });
  GetUpResult r;
  double standing_for = 0.0;
  // --snapshots: the robot from its side every 0.2 s from 0.2 s, tiled into one image.
  std::unique_ptr<engine::OffscreenRenderer> renderer;
  std::vector<cv::Mat> tiles;
  if (!snapshots.empty()) renderer = std::make_unique<engine::OffscreenRenderer>();
  const Vec3 side(-std::sin(yaw), std::cos(yaw), 0.0);
  // The view's distance and aim scale with the robot (a Nao's stance: 0.9 m away, 0.2 m up).
  const double size = model.soleDepth(model.pose("stand")) / 0.31;
  for (int i = 0; i < 1200; ++i) {
    t.period();
    if (c.verbose && i % 10 == 0) {
      const engine::Pose p = w.torsoPose(0);
      // The torso's x axis (forward), z axis (up) and y axis (left), world z
      // components: forward > 0 leans back, up < 0 is upside down, left > 0
      // rolled onto the right side.
      std::fprintf(stderr, "t %.2f %-10s tilt %.2f torso z %.3f forward %.2f up %.2f left %.2f\n",
                   i * dt, agents::motionStateName(motion.state()), motion.tilt(),
                   p.translation().z(), p.linear()(2, 0), p.linear()(2, 2), p.linear()(2, 1));
      traceSupport(w, position);
    }
    if (renderer && i % 20 == 0 && i >= 20 && tiles.size() < 36) {
      const Vec3 centre = w.torsoPose(0).translation();
      const Vec3 at(centre.x(), centre.y(), 0.2 * size);
      const engine::RenderView view =
          engine::pinholeView(world::lookAtPose(at + 0.9 * size * side, at), 320, 240, 0.75, 0.57);
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
  if (renderer && !tiles.empty()) writeTiles(tiles, snapshots);
  return r;
}

}  // namespace simsoccer::apps::motion
