#include "simsoccer/world/perception.hpp"

#include <cmath>

#include "simsoccer/world/render_scene.hpp"

namespace simsoccer::world {
namespace {

// Image sizes the frustums are taken from (the V6's practice: top 640x480,
// bottom 320x240, for a robot's first and second camera); only the aspect
// matters.
constexpr int kSize[2][2] = {{640, 480}, {320, 240}};

// The robot frame: under the torso, heading along its yaw.
engine::Pose robotFrame(const World& world, RobotId r) {
  const engine::Pose torso = world.torsoPose(r);
  const Vec3 x = torso.linear().col(0);
  engine::Pose f = engine::Pose::Identity();
  f.rotate(Eigen::AngleAxisd(std::atan2(x.y(), x.x()), Vec3::UnitZ()));
  f.translation() = Vec3(torso.translation().x(), torso.translation().y(), 0.0);
  return f;
}

}  // namespace

PerceptionSystem::PerceptionSystem(const World& world, const PerceptionSettings& settings)
    : settings_(settings),
      noise_(world.scenario().seed * 0x2545F4914F6CDD1DULL + 17),
      uniform_(world.scenario().seed * 0x9E3779B97F4A7C15ULL + 29) {
  state_.resize(world.robotCount());
  pose_error_.assign(world.robotCount(), {0.0, 0.0, 0.0});
  for (RobotId r = 0; r < world.robotCount(); ++r)
    for (RobotId o = 0; o < world.robotCount(); ++o)
      if (o != r) {
        PerceivedObject p;
        p.kind = PerceivedKind::Robot;
        p.team = world.robot(o).team;
        state_[r].robots.push_back(p);
      }
  // Posts: the first two goal shapes of each goal are its posts; a point 0.3 m up.
  size_t k = 0;
  for (int side : {-1, 1}) {
    const auto shapes = world.field().goalShapes(side);
    for (size_t i = 0; i < 2; ++i) {
      const Vec3 c = shapes[i].pose.translation();
      posts_[k++] = Vec3(c.x(), c.y(), 0.3);
    }
  }
  for (auto& p : state_)
    for (auto& post : p.posts) post.kind = PerceivedKind::GoalPost;
  views_.resize(world.robotCount());
  for (RobotId r = 0; r < world.robotCount(); ++r) {
    const robots::RobotModel& model = *world.robot(r).model;
    for (size_t c = 0; c < std::min(model.cameraCount(), views_[r].size()); ++c)
      views_[r][c] = robotCameraView(world, r, model.camera(c), kSize[c][0], kSize[c][1]);
  }
}

double PerceptionSystem::uniform() {
  return static_cast<double>(uniform_() >> 11) * 0x1.0p-53;
}

bool PerceptionSystem::inFrustum(const engine::RenderView& v, const engine::Pose& from_field,
                                 const Vec3& point) {
  double u = 0, w = 0;
  if (!engine::projectCameraPoint(v, from_field * point, u, w)) return false;
  return u >= 0 && u < v.width && w >= 0 && w < v.height;
}

// Whether the segment from `a` to `b` passes through a robot's body,
// approximated by a vertical cylinder (radius 0.12 m, up to 0.58 m).
bool PerceptionSystem::blockedByRobot(RobotId skip_a, RobotId skip_b, const Vec3& a,
                                      const Vec3& b) const {
  constexpr double kRadius = 0.12;
  // The segment's box widened by more than the radius: a torso outside it is
  // clear without the closest-approach arithmetic (the same answers).
  constexpr double kReach = kRadius + 0.01;
  const double x_lo = std::min(a.x(), b.x()) - kReach, x_hi = std::max(a.x(), b.x()) + kReach;
  const double y_lo = std::min(a.y(), b.y()) - kReach, y_hi = std::max(a.y(), b.y()) + kReach;
  const Eigen::Vector2d d2(b.x() - a.x(), b.y() - a.y());
  const double len2 = d2.squaredNorm();
  for (RobotId r = 0; r < torsos_.size(); ++r) {
    if (r == skip_a || r == skip_b) continue;
    const Vec3& c = torsos_[r];
    if (c.x() < x_lo || c.x() > x_hi || c.y() < y_lo || c.y() > y_hi) continue;
    // Closest approach in the ground plane along the segment.
    const Eigen::Vector2d a2(a.x() - c.x(), a.y() - c.y());
    const double t = len2 > 0 ? std::clamp(-a2.dot(d2) / len2, 0.0, 1.0) : 0.0;
    if ((a2 + t * d2).squaredNorm() > kRadius * kRadius) continue;
    const double z = a.z() + t * (b.z() - a.z());
    if (t > 0.02 && t < 0.98 && z < 0.58) return true;
  }
  return false;
}

void PerceptionSystem::observe(const World& world, const Viewpoint& from, const Vec3& point,
                               double range, PerceivedObject& object, RobotId skip) {
  object.in_view = false;
  const Vec3 rel = from.to_robot * point;
  // Out of range before the frustums: the same answer, and most of a crowded field's
  // robots cost no projection. Clearly out (the squared distance past the range by more
  // than rounding) costs no hypot either.
  if (settings_.realistic &&
      rel.x() * rel.x() + rel.y() * rel.y() > range * range * (1.0 + 1e-12))
    return;
  const double distance = std::hypot(rel.x(), rel.y());
  if (settings_.realistic && distance > range) return;
  int camera = -1;
  for (int c = 0; c < static_cast<int>(from.camera_count) && camera < 0; ++c)
    if (inFrustum(from.cameras[static_cast<size_t>(c)], from.from_field[static_cast<size_t>(c)],
                  point))
      camera = c;
  if (camera < 0) return;
  if (settings_.realistic) {
    const Vec3 eye = from.cameras[static_cast<size_t>(camera)].pose.translation();
    if (blockedByRobot(from.robot, skip, eye, point)) return;
    if (uniform() < settings_.miss_base + settings_.miss_per_metre * distance) return;
    const double d = distance * (1.0 + settings_.distance_noise * noise_());
    const double bearing = std::atan2(rel.y(), rel.x()) + settings_.bearing_noise * noise_();
    object.x = d * std::cos(bearing);
    object.y = d * std::sin(bearing);
  } else {
    object.x = rel.x();
    object.y = rel.y();
  }
  object.in_view = true;
  object.camera = camera;
  object.last_seen = world.time();
}

void PerceptionSystem::updatePoseErrors(double time) {
  // e' = a e + sqrt(1 - a^2) sigma n keeps the standard deviation sigma at every step; a = 0
  // (the first period, or no correlation time) draws each error afresh.
  const double tau = settings_.pose_noise_time;
  const double a = pose_error_time_ < 0.0 || tau <= 0.0
                       ? 0.0
                       : std::exp(-std::max(0.0, time - pose_error_time_) / tau);
  const double fresh = std::sqrt(1.0 - a * a);
  pose_error_time_ = time;
  for (std::array<double, 3>& e : pose_error_) {
    e[0] = a * e[0] + fresh * settings_.pose_noise_xy * noise_();
    e[1] = a * e[1] + fresh * settings_.pose_noise_xy * noise_();
    e[2] = a * e[2] + fresh * settings_.pose_noise_yaw * noise_();
  }
}

void PerceptionSystem::update(const World& world) {
  if (!settings_.enabled) return;
  const uint64_t tick = world.controlTick();
  const Vec3 ball = world.ballState().pose.translation();
  torsos_.resize(world.robotCount());
  for (RobotId r = 0; r < world.robotCount(); ++r) torsos_[r] = world.torsoPose(r).translation();
  if (settings_.realistic) updatePoseErrors(world.time());
  for (RobotId r = 0; r < world.robotCount(); ++r) {
    Perception& p = state_[r];
    p.tick = tick;
    p.time = world.time();
    // The robot's frame and camera views, once for all the objects it looks at.
    Viewpoint from{r, robotFrame(world, r), {}, {}, {}};
    from.to_robot = from.frame.inverse(Eigen::Isometry);
    const robots::RobotModel& model = *world.robot(r).model;
    from.camera_count = std::min(model.cameraCount(), from.cameras.size());
    for (size_t c = 0; c < from.camera_count; ++c) {
      from.cameras[c] = views_[r][c];
      from.cameras[c].pose = robotCameraPose(world, r, model.camera(c));
      from.from_field[c] = from.cameras[c].pose.inverse(Eigen::Isometry);
    }
    const engine::Pose& frame = from.frame;
    // Where the robot thinks it is.
    const double yaw = std::atan2(frame.linear()(1, 0), frame.linear()(0, 0));
    p.self_x = frame.translation().x();
    p.self_y = frame.translation().y();
    p.self_yaw = yaw;
    if (settings_.realistic) {
      const std::array<double, 3>& e = pose_error_[r];
      p.self_x += e[0];
      p.self_y += e[1];
      p.self_yaw = std::remainder(p.self_yaw + e[2], 2 * M_PI);
    }
    observe(world, from, ball, settings_.ball_range, p.ball, r);
    if (settings_.realistic && !p.ball.in_view && uniform() < settings_.false_ball_rate) {
      // A false ball somewhere ahead (a white robot part, a line crossing).
      const double d = 0.5 + 3.0 * uniform(), b = (uniform() - 0.5) * 1.0;
      p.ball.x = d * std::cos(b);
      p.ball.y = d * std::sin(b);
      p.ball.in_view = true;
      p.ball.camera = 0;
      p.ball.last_seen = world.time();
    }
    for (size_t k = 0; k < posts_.size(); ++k)
      observe(world, from, posts_[k], settings_.post_range, p.posts[k], r);
    size_t i = 0;
    for (RobotId o = 0; o < world.robotCount(); ++o) {
      if (o == r) continue;
      observe(world, from, torsos_[o], settings_.robot_range, p.robots[i++], o);
    }
  }
}

}  // namespace simsoccer::world
