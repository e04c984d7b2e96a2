// What each robot's cameras would see, computed geometrically from the two
// camera frustums (not from images): the ball, the goal posts and the other
// robots, relative to the robot, with in-view flags and when each was last
// seen; plus a noisy self-pose standing in for a localisation module.
//
// Profiles (scenario `perception:` block):
//   ideal      - exact positions of everything inside a camera's frustum;
//   realistic  - limited range, occlusion by robots, misses that grow with
//                distance, distance and bearing noise, occasional false balls,
//                seeded (the same run gives the same perception).
// Robot frame: origin under the torso, x forward along the torso's heading, y left.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "simsoccer/engine/offscreen_renderer.hpp"
#include "simsoccer/engine/random.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::world {

enum class PerceivedKind : uint8_t { Ball = 0, GoalPost = 1, Robot = 2 };

struct PerceivedObject {
  PerceivedKind kind = PerceivedKind::Ball;
  int team = -1;            // robots: the jersey's team; posts: -1
  bool in_view = false;     // seen this period
  int camera = -1;          // 0 top, 1 bottom (the one that saw it)
  double x = 0.0, y = 0.0;  // robot frame, m (the last sighting when not in view)
  double last_seen = -1.0;  // sim time, s (-1: never)
};

struct Perception {
  uint64_t tick = 0;
  double time = 0.0;
  PerceivedObject ball;
  std::array<PerceivedObject, 4> posts;  // -x goal right, left; +x goal right, left (field frame)
  std::vector<PerceivedObject> robots;   // every other robot, in world order
  double self_x = 0.0, self_y = 0.0, self_yaw = 0.0;  // estimated pose, field frame
};

class PerceptionSystem {
 public:
  PerceptionSystem(const World& world, const PerceptionSettings& settings);
  // Updates every robot's perception from the world's current state.
  void update(const World& world);
  const Perception& perception(RobotId r) const { return state_.at(r); }
  const PerceptionSettings& settings() const { return settings_; }

  // Whether a field-frame point is inside a camera view's frustum (and in front of it).
  static bool inFrustum(const engine::RenderView& view, const engine::Pose& from_field,
                        const Vec3& point);

 private:
  // One robot's view of the world this period: its frame and its cameras.
  struct Viewpoint {
    RobotId robot;
    engine::Pose frame;                         // robot frame in the field
    engine::Pose to_robot;                      // its inverse: field to robot frame
    std::array<engine::RenderView, 2> cameras;  // the robot's first two cameras
    std::array<engine::Pose, 2> from_field;     // field to each camera's frame
    size_t camera_count = 0;
  };
  void observe(const World& world, const Viewpoint& from, const Vec3& point, double range,
               PerceivedObject& object, RobotId skip);
  void updatePoseErrors(double time);
  bool blockedByRobot(RobotId skip_a, RobotId skip_b, const Vec3& a, const Vec3& b) const;

  PerceptionSettings settings_;
  std::vector<Perception> state_;
  std::array<Vec3, 4> posts_;
  std::vector<Vec3> torsos_;  // every robot's torso this period (occlusion)
  // Per robot, the self-pose estimate's error (x m, y m, yaw rad): a first-order Gauss-Markov
  // process with the profile's standard deviations and correlation time.
  std::vector<std::array<double, 3>> pose_error_;
  double pose_error_time_ = -1.0;  // sim time of its last update (-1: not started)
  // Every robot's first two camera views with their intrinsics (constant: worked
  // out once); their poses are set each period.
  std::vector<std::array<engine::RenderView, 2>> views_;
  double uniform();           // [0, 1), the same on every standard library
  engine::NormalSampler noise_;
  std::mt19937_64 uniform_;
};

}  // namespace simsoccer::world
