// The geometric perception: in-view flags against frustums worked out by
// hand, relative positions, memory, head motion, and the realistic profile's
// range, occlusion, noise, misses and determinism.
#include <gtest/gtest.h>

#include <cmath>

#include "simsoccer/world/perception.hpp"
#include "simsoccer/world/render_scene.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using engine::Vec3;

namespace {

// One Nao at (-2, 1.5) facing +x (a second robot far away unless moved).
world::Scenario scene(int robots = 1) {
  world::Scenario s = test::scenario(robots);
  s.robots[0].x = -2.0;
  s.robots[0].y = 1.5;
  s.robots[0].yaw = 0.0;
  if (robots > 1) {
    s.robots[1].x = 3.5;
    s.robots[1].y = -2.5;
  }
  s.ball_position = {-1.0, 1.5, -1.0};
  return s;
}

// The frustum by hand: the point in the camera frame (x forward, y left,
// z up) within half the field of view each way.
bool byHand(const world::World& w, const char* camera, const Vec3& p) {
  const engine::RenderView v = world::robotCameraView(w, 0, camera, 640, 480);
  const Vec3 c = v.pose.inverse() * p;
  // The V6's documented field of view (docs/reference.md): 56.3 x 43.7 deg.
  constexpr double kHorizontal = 56.3 * M_PI / 180.0, kVertical = 43.7 * M_PI / 180.0;
  return c.x() > 0 && std::abs(std::atan2(c.y(), c.x())) < 0.5 * kHorizontal &&
         std::abs(std::atan2(c.z(), c.x())) < 0.5 * kVertical;
}

}  // namespace

TEST(Perception, InViewFlagsMatchTheFrustumsWorkedOutByHand) {
  world::World w(scene());
  world::PerceptionSettings ideal;
  ideal.enabled = true;
  world::PerceptionSystem perception(w, ideal);
  int agree = 0, seen = 0, total = 0;
  for (double x = -3.5; x <= 1.0; x += 0.25)
    for (double y = -0.5; y <= 3.5; y += 0.25) {
      test::putBallOnCarpet(w, x, y);
      perception.update(w);
      const Vec3 ball = w.ballState().pose.translation();
      const bool expected = byHand(w, "CameraTop", ball) || byHand(w, "CameraBottom", ball);
      const auto& b = perception.perception(0).ball;
      agree += b.in_view == expected;
      seen += b.in_view;
      ++total;
      if (b.in_view) {  // ideal: exact relative position (robot frame: x forward)
        const Vec3 torso = w.torsoPose(0).translation();
        EXPECT_NEAR(b.x, ball.x() - torso.x(), 0.01);
        EXPECT_NEAR(b.y, ball.y() - torso.y(), 0.01);
      }
    }
  std::printf("%d of %d ball positions agree with the hand-worked frustums; %d in view\n", agree,
              total, seen);
  EXPECT_EQ(agree, total);
  EXPECT_GT(seen, 20);
  EXPECT_LT(seen, total - 20);
}

TEST(Perception, RemembersWhereAndWhenTheBallWasLastSeenAndHeadTurnsBringItIn) {
  world::World w(scene());
  world::PerceptionSettings ideal;
  ideal.enabled = true;
  world::PerceptionSystem perception(w, ideal);
  test::putBallOnCarpet(w, -1.0, 1.5);  // 1 m ahead
  perception.update(w);
  const auto seen = perception.perception(0).ball;
  ASSERT_TRUE(seen.in_view);
  EXPECT_NEAR(seen.x, 1.0, 0.02);
  w.stepControlPeriod();
  test::putBallOnCarpet(w, -1.2, 2.8);  // 58 degrees to the left: outside both frustums
  perception.update(w);
  const auto lost = perception.perception(0).ball;
  EXPECT_FALSE(lost.in_view);
  EXPECT_EQ(lost.last_seen, seen.last_seen);  // the last sighting is kept
  EXPECT_NEAR(lost.x, seen.x, 1e-12);
  // Turning the head 1 rad to the left brings it into view.
  const int head_yaw = w.robot(0).model->body->jointIndex("HeadYaw");
  w.setJointTarget(0, head_yaw, 1.0, 1.0);
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();
  test::putBallOnCarpet(w, -1.2, 2.8);
  perception.update(w);
  EXPECT_TRUE(perception.perception(0).ball.in_view);
  EXPECT_NEAR(perception.perception(0).ball.y, 1.3, 0.05);
}

TEST(Perception, GoalPostsAheadAreSeenWhereTheyStand) {
  world::Scenario s = scene();
  s.robots[0].x = 1.5;
  s.robots[0].y = 0.0;
  world::World w(s);
  world::PerceptionSettings ideal;
  ideal.enabled = true;
  world::PerceptionSystem perception(w, ideal);
  perception.update(w);
  const auto& p = perception.perception(0);
  EXPECT_FALSE(p.posts[0].in_view);  // the goal behind
  EXPECT_FALSE(p.posts[1].in_view);
  for (size_t k : {2u, 3u}) {
    ASSERT_TRUE(p.posts[k].in_view) << k;
    EXPECT_NEAR(p.posts[k].x, 4.5 + 0.05 - 1.5, 0.06);  // goal line + post radius, from x = 1.5
    EXPECT_NEAR(std::abs(p.posts[k].y), 0.8 + 0.05, 0.06);
  }
  EXPECT_NEAR(p.self_x, 1.5, 0.02);  // ideal self-pose
}

TEST(Perception, RealisticProfileHasRangeOcclusionNoiseAndMissesAndIsSeeded) {
  auto run = [](uint64_t seed, bool blocker, double ball_x) {
    world::Scenario s = scene(2);
    s.seed = seed;
    if (blocker) {  // the other robot between the observer and the ball
      s.robots[1].x = -1.0;
      s.robots[1].y = 1.5;
    }
    world::World w(s);
    world::PerceptionSettings p;
    p.enabled = true;
    p.realistic = true;
    world::PerceptionSystem perception(w, p);
    test::putBallOnCarpet(w, ball_x, 1.5);
    std::vector<double> distances;
    int seen = 0;
    for (int i = 0; i < 400; ++i) {
      perception.update(w);
      const auto& b = perception.perception(0).ball;
      if (b.in_view) {
        ++seen;
        distances.push_back(std::hypot(b.x, b.y));
      }
    }
    return std::pair{seen, distances};
  };
  // 2 m ahead: seen most of the time, distance noise about 5 %.
  const auto [seen, d] = run(1, false, 0.0);
  double mean = 0, var = 0;
  for (double x : d) mean += x / static_cast<double>(d.size());
  for (double x : d) var += (x - mean) * (x - mean) / static_cast<double>(d.size());
  std::printf("realistic, ball 2 m ahead: seen %d of 400, mean %.3f m, std %.3f m\n", seen, mean,
              std::sqrt(var));
  EXPECT_GT(seen, 300);  // misses: 2 % + 4 % per metre = 10 %, plus a few false balls counted in
  EXPECT_LT(seen, 395);
  EXPECT_NEAR(mean, 2.0, 0.05);
  EXPECT_NEAR(std::sqrt(var), 0.10, 0.04);
  // Same seed, same perception; another seed, another.
  EXPECT_EQ(run(1, false, 0.0).second, d);
  EXPECT_NE(run(2, false, 0.0).second, d);
  // Behind a robot: only the odd false ball.
  EXPECT_LT(run(1, true, 0.0).first, 10);
  // Beyond the range (6 m): not seen (false balls aside).
  EXPECT_LT(run(1, false, 4.3).first, 10);
}

// The self-pose estimate stands in for a localisation filter: its error has the profile's
// standard deviation but drifts (correlation time pose_noise_time), so that from one period to
// the next it moves by millimetres, as a filter's output does; pose_noise_time 0 draws each
// period's error afresh.
TEST(Perception, SelfPoseErrorDriftsWithTheProfilesDeviationAndCorrelationTime) {
  auto run = [](double correlation_time) {
    world::World w(scene());
    world::PerceptionSettings ideal, realistic;
    ideal.enabled = realistic.enabled = realistic.realistic = true;
    ideal.realistic = false;
    realistic.pose_noise_time = correlation_time;
    world::PerceptionSystem truth(w, ideal), estimate(w, realistic);
    std::vector<double> error_x, error_yaw;
    for (int i = 0; i < 6000; ++i) {  // 60 s of 10 ms periods
      w.stepControlPeriod();
      truth.update(w);
      estimate.update(w);
      error_x.push_back(estimate.perception(0).self_x - truth.perception(0).self_x);
      error_yaw.push_back(
          std::remainder(estimate.perception(0).self_yaw - truth.perception(0).self_yaw, 2 * M_PI));
    }
    auto rms = [](const std::vector<double>& v) {
      double s = 0.0;
      for (double x : v) s += x * x;
      return std::sqrt(s / static_cast<double>(v.size()));
    };
    std::vector<double> step_x;  // the error's change from one period to the next
    for (size_t i = 1; i < error_x.size(); ++i) step_x.push_back(error_x[i] - error_x[i - 1]);
    return std::array<double, 3>{rms(error_x), rms(error_yaw), rms(step_x)};
  };
  const auto drifting = run(1.0), white = run(0.0);
  std::printf(
      "self-pose error: 1 s correlation: %.4f m, %.4f rad, %.4f m per period; white: %.4f m, "
      "%.4f rad, %.4f m per period\n",
      drifting[0], drifting[1], drifting[2], white[0], white[1], white[2]);
  // 60 s holds about 30 correlation times: the deviation within a quarter of 0.05 m.
  EXPECT_NEAR(drifting[0], 0.05, 0.0125);
  EXPECT_NEAR(drifting[1], 0.03, 0.0075);
  // sqrt(2 (1 - exp(-0.01))) = 0.14 of the deviation per period, against sqrt(2) white.
  EXPECT_NEAR(drifting[2], 0.05 * 0.141, 0.002);
  EXPECT_NEAR(white[0], 0.05, 0.004);
  EXPECT_NEAR(white[1], 0.03, 0.0025);
  EXPECT_NEAR(white[2], 0.05 * std::sqrt(2.0), 0.006);
}
