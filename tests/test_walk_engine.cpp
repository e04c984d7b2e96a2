// The walk engine's own geometry, without physics: foot lift, step lengths,
// odometry, stopping. (Walking on the physics: bench motion and the DDS test.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "simsoccer/agents/motion/gait.hpp"
#include "simsoccer/agents/motion/kick_engine.hpp"
#include "simsoccer/agents/motion/walk_engine.hpp"
#include "simsoccer/engine/config.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using agents::Leg;

namespace {

struct Feet {
  agents::Pose left, right;
};

Feet feetOf(const agents::WalkEngine& e, const std::vector<double>& q) {
  agents::LegAngles l, r;
  for (int i = 0; i < 6; ++i) {
    l[i] = q[static_cast<size_t>(e.kinematics().joints(Leg::Left)[i])];
    r[i] = q[static_cast<size_t>(e.kinematics().joints(Leg::Right)[i])];
  }
  return {e.kinematics().forward(Leg::Left, l), e.kinematics().forward(Leg::Right, r)};
}

}  // namespace

TEST(WalkEngine, SwingFootLiftsAndLandsAtItsPlacement) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  agents::WalkParameters p;
  p.hip_roll_compensation =
      0.0;  // pure geometry: the sag compensation bends the support leg on purpose
  agents::WalkEngine e(model, p);
  std::vector<double> q = model.pose("stand");
  e.update(0.01, {}, q);
  const Feet standing = feetOf(e, q);
  EXPECT_NEAR(standing.left.translation().z(), -p.ankle_height, 1e-6);
  EXPECT_NEAR(standing.left.translation().y() - standing.right.translation().y(), p.step_width,
              1e-6);
  e.setVelocity(0.2, 0.0, 0.0);
  double apex = -1.0;
  for (int i = 0; i < 25; ++i) {  // the first step: the left foot swings
    e.update(0.01, {}, q);
    const Feet f = feetOf(e, q);
    apex = std::max(apex, f.left.translation().z() - f.right.translation().z());
    EXPECT_NEAR(f.right.translation().z(), -p.ankle_height, 1e-6);  // the support foot stays down
  }
  EXPECT_NEAR(apex, p.foot_lift, 0.0005);
}

// A walk started again soon after it stopped first shifts the weight: for one step the torso
// sways over the right foot and both feet stay down; then the right foot steps. Started after
// standing longer (or with start_shift_time 0, the Nao's), the left foot lifts at once.
TEST(WalkEngine, AWalkStartedSoonAfterItStoppedFirstShiftsTheWeight) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  agents::WalkParameters p;
  p.start_shift_time = 1.0;
  p.hip_roll_compensation = 0.0;  // pure geometry (as above)
  agents::WalkEngine e(model, p);
  std::vector<double> q = model.pose("stand");
  const int step = static_cast<int>(std::lround(p.step_period / 0.01));
  // Lift of each foot above the other, highest over the next `periods` periods.
  const auto lifts = [&](int periods) {
    std::pair<double, double> most{-1.0, -1.0};
    for (int i = 0; i < periods; ++i) {
      e.update(0.01, {}, q);
      const Feet f = feetOf(e, q);
      const double d = f.left.translation().z() - f.right.translation().z();
      most = {std::max(most.first, d), std::max(most.second, -d)};
    }
    return most;
  };
  // Never walked: the left foot steps at once.
  e.setVelocity(0.1, 0.0, 0.0);
  EXPECT_NEAR(lifts(step - 1).first, p.foot_lift, 0.001);
  lifts(3 * step);
  e.stop();
  for (int i = 0; i < 1000 && e.walking(); ++i) e.update(0.01, {}, q);
  ASSERT_FALSE(e.walking());
  lifts(30);  // stood 0.3 s
  const double walked = e.odometry().x;
  e.setVelocity(0.1, 0.0, 0.0);
  const auto shift = lifts(step - 1);
  EXPECT_NEAR(shift.first, 0.0, 1e-6);  // both feet down
  EXPECT_NEAR(shift.second, 0.0, 1e-6);
  EXPECT_EQ(e.odometry().x, walked);  // nor did the body move on
  lifts(2);                           // the next step: the right foot swings
  const auto next = lifts(step - 3);
  EXPECT_NEAR(next.second, p.foot_lift, 0.001);
  EXPECT_LT(next.first, 1e-6);
  // Stood longer than start_shift_time: no weight shift.
  e.stop();
  for (int i = 0; i < 1000 && e.walking(); ++i) e.update(0.01, {}, q);
  lifts(110);
  e.setVelocity(0.1, 0.0, 0.0);
  EXPECT_NEAR(lifts(step - 1).first, p.foot_lift, 0.001);
}

// A step whose time is up while the torso still leans over the support foot waits in double
// support (the swing foot down) until the lean is back, at most max_support_hold.
TEST(WalkEngine, AStepWaitsInDoubleSupportWhileTheTorsoLeansOverItsSupportFoot) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  agents::WalkParameters p;
  p.max_support_hold = 0.3;
  std::vector<double> q = model.pose("stand");
  const agents::WalkSensors upright{}, leaning_right{.roll = 0.2}, leaning_left{.roll = -0.2};
  auto walkOnTheSpot = [&](agents::WalkEngine& e, const agents::WalkSensors& imu, int periods) {
    for (int i = 0; i < periods; ++i) e.update(0.01, imu, q);
  };
  // The first step stands on the right foot (the left one swings); 0.25 s, then 0.05 s more.
  agents::WalkEngine held(model, p);
  held.setVelocity(0.0, 0.0, 0.0);
  walkOnTheSpot(held, leaning_right, 30);
  EXPECT_EQ(held.supportLeg(), Leg::Right);
  EXPECT_DOUBLE_EQ(held.phase(), 1.0);
  const Feet down = feetOf(held, q);
  EXPECT_NEAR(down.left.translation().z(), down.right.translation().z(), 1e-6);
  walkOnTheSpot(held, upright, 1);  // the lean is back: the left foot takes the weight
  EXPECT_EQ(held.supportLeg(), Leg::Left);
  EXPECT_LT(held.phase(), 0.1);

  // Leaning towards the swing foot, or with the hold off, the step ends on time.
  agents::WalkEngine other_way(model, p);
  other_way.setVelocity(0.0, 0.0, 0.0);
  walkOnTheSpot(other_way, leaning_left, 30);
  EXPECT_EQ(other_way.supportLeg(), Leg::Left);
  agents::WalkEngine open_loop(model);
  open_loop.setVelocity(0.0, 0.0, 0.0);
  walkOnTheSpot(open_loop, leaning_right, 30);
  EXPECT_EQ(open_loop.supportLeg(), Leg::Left);

  // A lean that lasts: the step ends after max_support_hold anyway.
  agents::WalkEngine lasting(model, p);
  lasting.setVelocity(0.0, 0.0, 0.0);
  walkOnTheSpot(lasting, leaning_right, 50);  // 0.25 s of step, 0.25 s held
  EXPECT_EQ(lasting.supportLeg(), Leg::Right);
  walkOnTheSpot(lasting, leaning_right, 10);
  EXPECT_EQ(lasting.supportLeg(), Leg::Left);
}

TEST(WalkEngine, OdometryFollowsTheCommandAndStopEndsWithFeetTogether) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  agents::WalkEngine e(model);
  std::vector<double> q = model.pose("stand");
  e.setVelocity(0.2, 0.0, 0.0);
  for (int i = 0; i < 400; ++i) e.update(0.01, {}, q);  // 4 s
  // Ramped up by 0.02 m per step to 0.05 m per step (0.2 m/s at 4 steps/s).
  EXPECT_GT(e.odometry().x, 0.7);
  EXPECT_LT(e.odometry().x, 0.85);
  EXPECT_NEAR(e.odometry().y, 0.0, 1e-9);
  e.stop();
  for (int i = 0; i < 300 && e.walking(); ++i) e.update(0.01, {}, q);
  EXPECT_FALSE(e.walking());
  const Feet f = feetOf(e, q);
  EXPECT_NEAR(f.left.translation().x(), f.right.translation().x(), 1e-3);  // side by side
  EXPECT_NEAR(f.left.translation().z(), f.right.translation().z(), 1e-6);
  // A command beyond the limits is scaled into them.
  agents::WalkEngine fast(model);
  fast.setVelocity(5.0, 0.0, 0.0);
  for (int i = 0; i < 1000; ++i) fast.update(0.01, {}, q);
  EXPECT_NEAR(fast.odometry().x / 10.0, fast.parameters().max_forward / 0.25, 0.03);
}

// Turning, the swing foot turns only while it is off the ground: near lift-off and touch-down
// (a tenth of the step at either end) it keeps its yaw, and it lands turned by the whole step.
// (The K1: its hips turn each leg on its own; the Nao's shared hip joint tilts the yaw a little.)
TEST(WalkEngine, TheSwingFootTurnsOnlyWhileItIsOffTheGround) {
  const robots::RobotModel model = robots::loadRobotModel(test::boosterK1());
  agents::WalkParameters p =
      agents::loadGaitIn(test::sourceDir() / "configs" / "motions" / "booster_k1").walk;
  p.hip_roll_compensation = 0.0;  // pure geometry: it tilts the support foot on purpose
  agents::WalkEngine e(model, p);
  std::vector<double> q = model.pose("stand");
  e.update(0.01, {}, q);
  e.setVelocity(0.0, 0.0, 0.8);
  const auto yawOf = [](const Eigen::Matrix3d& r) { return std::atan2(r(1, 0), r(0, 0)); };
  double last_turn = 0.0, last_lift = 0.0;
  int turned_on_the_ground = 0, turned_off_it = 0;
  for (int i = 0; i < 50 && e.supportLeg() == Leg::Right; ++i) {  // the left foot's first step
    e.update(0.01, {}, q);
    const Feet f = feetOf(e, q);
    const double turn = yawOf(f.right.linear().transpose() * f.left.linear());
    const double lift = f.left.translation().z() - f.right.translation().z();
    // Turned since the last period: off the ground at one end of it at least.
    if (std::abs(turn - last_turn) > 1e-6)
      (std::max(lift, last_lift) > 0.3 * p.foot_lift ? turned_off_it : turned_on_the_ground) += 1;
    last_turn = turn;
    last_lift = lift;
  }
  EXPECT_EQ(turned_on_the_ground, 0);
  EXPECT_GT(turned_off_it, 20);
  EXPECT_GT(last_turn, 0.1);  // to the left
  // It landed turned by the step's whole turn: the support foot's yaw in the odometry.
  EXPECT_NEAR(last_turn, e.odometry().yaw, 1e-6);
}

// Turning on the spot may take larger turning steps and ramp up faster than while walking
// (max_turn_on_spot, max_turn_accel_on_spot); with a step forward wanted, the walk's limits hold.
TEST(WalkEngine, TurningOnTheSpotHasItsOwnLimits) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  std::vector<double> q = model.pose("stand");
  agents::WalkParameters p;
  p.max_turn_on_spot = 0.6;
  p.max_turn_accel_on_spot = 0.2;
  // The largest turning step over 3 s with the IMU's yaw standing still (the robot does not
  // turn at all, so the heading hold asks for ever more), and the first step's.
  const auto steps = [&](double forward) {
    agents::WalkEngine e(model, p);
    e.update(0.01, {}, q);
    e.setVelocity(forward, 0.0, 0.8);
    double largest = 0.0, first = -1.0, before = 0.0;
    for (int i = 0; i < 300; ++i) {
      const Leg support = e.supportLeg();
      e.update(0.01, {}, q);
      if (e.supportLeg() != support) {
        const double step = e.odometry().yaw - before;
        before = e.odometry().yaw;
        if (first < 0.0) first = step;
        largest = std::max(largest, step);
      }
    }
    return std::pair{first, largest};
  };
  const auto [first_on_spot, largest_on_spot] = steps(0.0);
  EXPECT_NEAR(largest_on_spot, 0.6, 1e-9);
  // The first step: twice the average (0.2, one ramp step) and half the heading error (0.2).
  EXPECT_NEAR(first_on_spot, 2 * 0.2 + 0.5 * 0.2, 1e-9);
  const auto [first_walking, largest_walking] = steps(0.1);
  EXPECT_NEAR(largest_walking, p.max_turn, 1e-9);
  EXPECT_NEAR(first_walking, 2 * p.max_turn_accel + 0.5 * p.max_turn_accel, 1e-9);
}

// The torso's yaw sways a little with the steps (about 0.01 rad). In step
// with the feet, the heading hold corrects it on every step, so a plain stop
// keeps stepping on the spot (a robot asked to stand: it holds its heading);
// settling to sit down, it stops.
TEST(WalkEngine, SettlesToAStopAlthoughTheYawSwaysWithTheSteps) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  agents::WalkEngine e(model);
  std::vector<double> q = model.pose("stand");
  const double period = e.parameters().step_period;
  // Each step's end reads +-0.012 rad, alternating with the swinging foot:
  // the correction's sign always matches the side that may turn.
  const auto yaw = [&](int i) { return -0.012 * std::cos(M_PI * i * 0.01 / period); };
  e.update(0.01, {}, q);  // its heading: yaw 0
  e.setVelocity(0.1, 0.0, 0.0);
  int i = 0;
  for (; i < 200; ++i) e.update(0.01, {.yaw = yaw(i)}, q);
  e.stop();
  for (int k = 0; k < 300; ++k, ++i) e.update(0.01, {.yaw = yaw(i)}, q);
  // 3 s later still stepping, correcting the sway: as documented (README,
  // Walk: every stop settling doubled the falls in 5 v 5 matches).
  EXPECT_TRUE(e.walking());
  e.stop(true);
  for (int k = 0; k < 300 && e.walking(); ++k, ++i)
    e.update(0.01, {.yaw = e.walking() ? yaw(i) : 0.0}, q);
  EXPECT_FALSE(e.walking());
  // A real heading error is still corrected before it stops.
  agents::WalkEngine off(model);
  off.setVelocity(0.1, 0.0, 0.0);
  for (int k = 0; k < 200; ++k) off.update(0.01, {}, q);
  off.stop(true);
  int turned = 0;
  for (int k = 0; k < 300 && off.walking(); ++k) {
    off.update(0.01, {.yaw = -0.2}, q);  // 0.2 rad right of its heading
    turned += std::abs(off.odometry().yaw) > 1e-6;
  }
  EXPECT_GT(turned, 0);
}

namespace {

// The sole of a foot link: the xy rectangle of its collision boxes, in the
// foot's frame (the sole is the boxes' bottom face).
std::vector<engine::Vec3> soleCorners(const engine::ArticulatedModel& body, int link) {
  std::vector<engine::Vec3> corners;
  for (const engine::Shape& s : body.links[static_cast<size_t>(link)].shapes) {
    if (s.type != engine::ShapeType::Box) continue;
    for (double sx : {-0.5, 0.5})
      for (double sy : {-0.5, 0.5})
        corners.push_back(
            s.pose * engine::Vec3(sx * s.extents.x(), sy * s.extents.y(), -0.5 * s.extents.z()));
  }
  return corners;
}

struct SupportMargins {
  double com = 1e9;       // m, least distance of the CoM's ground point inside the polygon
  double zmp = 1e9;       // m, the same for the ZMP (negative: outside)
  double zmp_mean = 0.0;  // m, mean ZMP margin
  int ticks = 0, single_support = 0;
  int zmp_outside = 0;  // ticks with the ZMP more than 5 mm outside
};

// Runs the walk engine on a planned command sequence (velocity, seconds) at
// 100 Hz and checks every tick's planned posture, forward kinematics of the
// commanded joint angles with the model's link masses: the support polygon is
// the support sole while the swing foot is off the ground, the hull of both
// soles while both are down. The ZMP follows the cart-table model of the CoM
// track, p = c - z_c / g * c'' (c'' by central differences in the frame of the
// ground, chained from one support foot to the next).
SupportMargins walkSupport(const robots::RobotModel& model,
                           const std::vector<std::pair<engine::Vec3, double>>& plan,
                           double skip_seconds = 0.0) {
  const engine::ArticulatedModel& body = *model.body;
  // The support hip's sag compensation bends the support leg on purpose
  // (the physical servo gives as much back): left out of the pure geometry.
  agents::WalkParameters parameters;
  parameters.hip_roll_compensation = 0.0;
  agents::WalkEngine e(model, parameters);
  std::vector<double> q = model.pose("stand");
  const int feet[2] = {body.linkIndex("LFoot"), body.linkIndex("RFoot")};
  const std::vector<engine::Vec3> soles[2] = {soleCorners(body, feet[0]),
                                              soleCorners(body, feet[1])};
  EXPECT_EQ(soles[0].size(), 4u);
  const double dt = 0.01, g = 9.81;
  SupportMargins m;
  engine::Pose ground_support = engine::Pose::Identity();  // the support foot in the ground frame
  int support = 1;
  double yaw = 0.0;  // the plan's torso yaw, fed back as the IMU's (heading hold)
  std::vector<engine::Vec3> com_track;
  std::vector<std::vector<cv::Point2f>> polygons;  // per tick, ground frame (mm)
  double zmp_sum = 0.0;
  int zmp_count = 0;
  const long skip_ticks = std::lround(skip_seconds / dt);
  for (const auto& [v, seconds] : plan) {
    if (v.isZero())
      e.stop();  // a zero command: finish the step and stand
    else
      e.setVelocity(v.x(), v.y(), v.z());
    for (int i = 0; i < static_cast<int>(std::lround(seconds / dt)); ++i) {
      e.update(dt, {.yaw = yaw}, q);
      body.applyMimic(q);
      const std::vector<engine::Pose> frames = body.linkFramesAt(q);  // torso frame
      const int now = e.supportLeg() == Leg::Left ? 0 : 1;
      if (now != support) {  // hand over: chain the ground frame through the two feet
        ground_support = ground_support * frames[static_cast<size_t>(feet[support])].inverse() *
                         frames[static_cast<size_t>(feet[now])];
        support = now;
      }
      const engine::Pose ground_torso =
          ground_support * frames[static_cast<size_t>(feet[support])].inverse();
      yaw = std::atan2(ground_torso.linear()(1, 0), ground_torso.linear()(0, 0));
      com_track.push_back(ground_torso * body.centreOfMass(frames));
      // The swing foot is down when its sole is within 0.5 mm of the ground.
      const engine::Pose ground_swing =
          ground_torso * frames[static_cast<size_t>(feet[1 - support])];
      double swing_low = 1e9;
      for (const engine::Vec3& c : soles[1 - support])
        swing_low = std::min(swing_low, (ground_swing * c).z());
      const double sole_z = (ground_support * soles[support][0]).z();
      std::vector<cv::Point2f> points;
      for (const engine::Vec3& c : soles[support]) {
        const engine::Vec3 p = ground_support * c;
        points.emplace_back(static_cast<float>(1000 * p.x()), static_cast<float>(1000 * p.y()));
      }
      const bool single = swing_low - sole_z > 0.0005;
      if (!single)
        for (const engine::Vec3& c : soles[1 - support]) {
          const engine::Vec3 p = ground_swing * c;
          points.emplace_back(static_cast<float>(1000 * p.x()), static_cast<float>(1000 * p.y()));
        }
      std::vector<cv::Point2f> hull;
      cv::convexHull(points, hull);
      polygons.push_back(hull);
      const engine::Vec3& c = com_track.back();
      if (static_cast<long>(com_track.size()) <= skip_ticks + 1) continue;  // the ramp
      m.com = std::min(m.com,
                       0.001 * cv::pointPolygonTest(hull,
                                                    cv::Point2f(static_cast<float>(1000 * c.x()),
                                                                static_cast<float>(1000 * c.y())),
                                                    true));
      ++m.ticks;
      m.single_support += single ? 1 : 0;
      // The ZMP of the previous tick (central difference needs this one).
      const size_t n = com_track.size();
      if (n >= 3) {
        const engine::Vec3& a = com_track[n - 3];
        const engine::Vec3& b = com_track[n - 2];
        const engine::Vec3 acc = (a - 2 * b + c) / (dt * dt);
        const engine::Vec3 zmp = b - (b.z() - sole_z) / g * acc;
        const double margin =
            0.001 * cv::pointPolygonTest(polygons[n - 2],
                                         cv::Point2f(static_cast<float>(1000 * zmp.x()),
                                                     static_cast<float>(1000 * zmp.y())),
                                         true);
        m.zmp = std::min(m.zmp, margin);
        zmp_sum += margin;
        if (margin < -0.005) ++m.zmp_outside;
        ++zmp_count;
      }
    }
  }
  m.zmp_mean = zmp_count ? zmp_sum / zmp_count : 0.0;
  return m;
}

}  // namespace

// The pattern generator's plan, its ZMP against the support polygon
// (issue: "the ZMP/CoM stays in the support polygon for a planned step
// sequence"), checked on the plan itself: forward kinematics of the commanded
// joint angles with the model's masses, no physics.
//  - Walking forward at full speed (after the 2 s ramp): the ZMP stays over
//    the support sole / both soles except at lift-off, where it may be up to
//    5 mm outside (the generator has no double-support phase: the ZMP must
//    jump from one foot to the other; measured up to 4.4 mm past the sole's inner
//    rear edge for one 10 ms tick).
//  - Known limits, measured and printed; only bounded (mean inside, at most
//    a fifth of the ticks more than 5 mm outside): the plan's body changes
//    velocity at once at a step boundary (ramps, stopping), an impulse that
//    puts the cart-table ZMP up to 0.35 m outside for one tick; in sideways
//    steps (open on one step, close on the next) the body moves over the
//    landing foot before it lands, the ZMP outside for the last fifth of the
//    opening step (107 of 599 ticks); turning 23, combined 61 ticks. The CoM
//    itself leaves the sole during single support by up to 54 mm (a dynamic
//    walk: it is the ZMP that has to stay in).
TEST(WalkEngine, PlannedZmpAgainstTheSupportPolygon) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  const SupportMargins steady = walkSupport(model, {{{0.3, 0.0, 0.0}, 6.0}}, 2.0);
  std::printf(
      "forward (steady) ticks %d (single support %d): ZMP margin min %.1f mm, mean %.1f "
      "mm; CoM margin min %.1f mm\n",
      steady.ticks, steady.single_support, 1000 * steady.zmp, 1000 * steady.zmp_mean,
      1000 * steady.com);
  EXPECT_GT(steady.single_support, steady.ticks / 2);  // it really stepped
  EXPECT_GT(steady.zmp, -0.005);
  EXPECT_GT(steady.zmp_mean, 0.015);
  struct Case {
    const char* name;
    std::vector<std::pair<engine::Vec3, double>> plan;
  };
  const std::vector<Case> cases{
      {"start, forward, stop", {{{0.3, 0.0, 0.0}, 4.0}, {{0.0, 0.0, 0.0}, 1.5}}},
      {"sideways", {{{0.0, 0.1, 0.0}, 3.0}, {{0.0, -0.1, 0.0}, 3.0}}},
      {"turning", {{{0.0, 0.0, 0.8}, 3.0}, {{0.0, 0.0, -0.8}, 3.0}}},
      {"combined", {{{0.15, 0.05, 0.4}, 3.0}, {{-0.1, -0.05, -0.3}, 3.0}}}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const SupportMargins m = walkSupport(model, c.plan);
    std::printf(
        "%-20s ticks %d (single support %d): ZMP margin min %.1f mm, mean %.1f mm, %d ticks "
        "> 5 mm outside; CoM margin min %.1f mm\n",
        c.name, m.ticks, m.single_support, 1000 * m.zmp, 1000 * m.zmp_mean, m.zmp_outside,
        1000 * m.com);
    EXPECT_GT(m.single_support, m.ticks / 2);
    EXPECT_GT(m.zmp_mean, 0.0);
    EXPECT_LE(m.zmp_outside, m.ticks / 5);  // measured: 6, 107, 23 and 61 of 549-599 ticks
  }
}

// After walking a K1's feet stand a few cm off the gait's stance. The kick starts from where
// they stand (its first targets keep the feet's measured offset: no push against the ground),
// puts the kicking foot in the gait's stance while it is lifted and ends there. Without measured
// angles, or with a foot off the ground, it starts from the gait's stance.
TEST(KickEngine, StartsFromTheStanceTheFeetStandInAndEndsInTheGaitsStance) {
  const robots::RobotModel model = robots::loadRobotModel(test::boosterK1());
  const agents::Gait gait = agents::loadGaitIn(test::sourceDir() / "configs/motions/booster_k1");
  const agents::WalkParameters& w = gait.walk;
  agents::WalkEngine walk(model, w);  // for its kinematics
  // The feet 0.17 m apart (not 0.19), the left one 1 cm ahead and turned 0.05 rad.
  auto footAt = [&](double x, double y, double yaw) {
    agents::Pose f = agents::Pose::Identity();
    f.translation() = engine::Vec3(x, y, -w.ankle_height);
    f.rotate(Eigen::AngleAxisd(yaw, engine::Vec3::UnitZ()));
    return f;
  };
  const agents::LegSolution stood =
      walk.kinematics().inverse(footAt(0.01, 0.085, 0.05), footAt(0.0, -0.085, 0.0));
  ASSERT_LT(stood.position_error, 1e-4);
  std::vector<double> measured = model.pose("stand");
  walk.kinematics().writeTargets(stood, measured);
  // The kicking (left) foot against the support (right) foot.
  auto offset = [&](const std::vector<double>& q) {
    const Feet f = feetOf(walk, q);
    return agents::Pose(f.right.inverse() * f.left);
  };
  const double dt = 0.01;
  agents::KickEngine kick(model, w, gait.kick);
  std::vector<double> q = measured;
  kick.start(Leg::Left, measured);
  kick.update(dt, engine::Vec3::Zero(), q);
  agents::Pose o = offset(q);
  EXPECT_NEAR(o.translation().x(), 0.01, 1e-3);
  EXPECT_NEAR(o.translation().y(), 0.17, 1e-3);
  EXPECT_NEAR(std::atan2(o.rotation()(1, 0), o.rotation()(0, 0)), 0.05, 2e-3);
  EXPECT_NEAR(o.translation().z(), 0.0, 1e-3);
  // Drawn back and lifted, it is where a kick from the gait's stance has it.
  agents::KickEngine nominal(model, w, gait.kick);
  std::vector<double> nominal_q = measured;
  nominal.start(Leg::Left);
  nominal.update(dt, engine::Vec3::Zero(), nominal_q);
  const agents::KickParameters& k = gait.kick;
  for (double t = dt; t < k.shift_time + k.lift_time - 0.5 * dt; t += dt) {
    kick.update(dt, engine::Vec3::Zero(), q);
    nominal.update(dt, engine::Vec3::Zero(), nominal_q);
  }
  o = offset(q);
  const agents::Pose lifted_nominal = offset(nominal_q);
  EXPECT_LT((o.translation() - lifted_nominal.translation()).norm(), 1e-3);
  EXPECT_LT(Eigen::AngleAxisd(o.rotation().transpose() * lifted_nominal.rotation()).angle(), 2e-3);
  EXPECT_GT(o.translation().z(), 0.5 * k.lift);
  while (kick.active()) kick.update(dt, engine::Vec3::Zero(), q);
  o = offset(q);
  EXPECT_NEAR(o.translation().x(), 0.0, 1e-3);
  EXPECT_NEAR(o.translation().y(), w.step_width, 1e-3);
  EXPECT_NEAR(o.translation().z(), 0.0, 1e-3);

  // No measured angles, or the kicking foot 3 cm up: the gait's stance from the start.
  const agents::LegSolution lifted = walk.kinematics().inverse(
      footAt(0.0, 0.085, 0.0) * Eigen::Translation3d(0, 0, 0.03), footAt(0.0, -0.085, 0.0));
  std::vector<double> lifted_q = model.pose("stand");
  walk.kinematics().writeTargets(lifted, lifted_q);
  for (const std::vector<double>& from : {std::vector<double>{}, lifted_q}) {
    agents::KickEngine fresh(model, w, gait.kick);
    fresh.start(Leg::Left, from);
    fresh.update(dt, engine::Vec3::Zero(), q);
    EXPECT_NEAR(offset(q).translation().y(), w.step_width, 1e-3);
  }
}

// A robot the referee moved mid-step stands with one foot ahead. The walk takes the feet where
// they stand (standing keeps them there: no sliding them on the carpet) and its first steps put
// them in the gait's stance; with a foot off the ground it keeps the gait's stance.
TEST(WalkEngine, StandsWhereTheFeetAreAndStepsIntoItsStance) {
  const robots::RobotModel model = robots::loadRobotModel(test::boosterK1());
  const agents::WalkParameters w =
      agents::loadGaitIn(test::sourceDir() / "configs/motions/booster_k1").walk;
  agents::WalkEngine e(model, w);
  auto footAt = [&](double x, double y, double yaw, double z = 0.0) {
    agents::Pose f = agents::Pose::Identity();
    f.translation() = engine::Vec3(x, y, z - w.ankle_height);
    f.rotate(Eigen::AngleAxisd(yaw, engine::Vec3::UnitZ()));
    return f;
  };
  auto jointsFor = [&](const agents::Pose& left, const agents::Pose& right) {
    std::vector<double> q = model.pose("stand");
    e.kinematics().writeTargets(e.kinematics().inverse(left, right), q);
    return q;
  };
  // The left foot against the right one in `q`'s targets.
  auto leftAgainstRight = [&](const std::vector<double>& q) {
    const Feet f = feetOf(e, q);
    const agents::Pose rel = f.right.inverse() * f.left;
    return engine::Vec3(rel.translation().x(), rel.translation().y(),
                        std::atan2(rel.linear()(1, 0), rel.linear()(0, 0)));
  };
  // Mid-step: the left foot 6 cm ahead, 0.18 m to the side, turned 0.1 rad.
  std::vector<double> q = jointsFor(footAt(0.03, 0.09, 0.1), footAt(-0.03, -0.09, 0.0));
  agents::WalkEngine walk(model, w);
  walk.standWhereTheFeetAre(q);
  std::vector<double> targets = q;
  for (int i = 0; i < 10; ++i) walk.update(0.01, {}, targets);
  EXPECT_LT((leftAgainstRight(targets) - engine::Vec3(0.06, 0.18, 0.1)).norm(), 2e-3);
  // A few steps on the spot, then stopped: side by side in the gait's stance.
  walk.setVelocity(0.0, 0.0, 0.0);
  for (int i = 0; i < 200; ++i) walk.update(0.01, {}, targets);
  walk.stop();
  for (int i = 0; i < 300 && walk.walking(); ++i) walk.update(0.01, {}, targets);
  ASSERT_FALSE(walk.walking());
  walk.update(0.01, {}, targets);
  EXPECT_LT((leftAgainstRight(targets) - engine::Vec3(0.0, w.step_width, 0.0)).norm(), 2e-3);
  // The left foot 3 cm up: the gait's stance.
  agents::WalkEngine lifted(model, w);
  lifted.standWhereTheFeetAre(jointsFor(footAt(0.0, 0.09, 0.0, 0.03), footAt(0.0, -0.09, 0.0)));
  lifted.update(0.01, {}, targets);
  EXPECT_LT((leftAgainstRight(targets) - engine::Vec3(0.0, w.step_width, 0.0)).norm(), 2e-3);
}

// After its keyframes the kick holds the stance until the torso has turned slower than
// calm_rate for calm_time, at most calm_wait longer; with calm_rate 0 it ends with its keyframes.
TEST(KickEngine, HoldsTheStanceUntilTheTorsoIsCalm) {
  const robots::RobotModel model = robots::loadRobotModel(test::boosterK1());
  agents::Gait gait = agents::loadGaitIn(test::sourceDir() / "configs/motions/booster_k1");
  gait.kick.calm_rate = 0.25;
  gait.kick.calm_time = 0.3;
  gait.kick.calm_wait = 2.0;
  const double dt = 0.01;
  // Seconds the kick lasts with the torso rocking (1 rad/s) until `rocking` s after the start.
  auto lasts = [&](const agents::KickParameters& k, double rocking) {
    agents::KickEngine kick(model, gait.walk, k);
    std::vector<double> q = model.pose("stand");
    kick.start(Leg::Right);
    double t = 0.0;
    while (kick.active() && t < 20.0) {
      kick.update(dt, engine::Vec3(t < rocking ? 1.0 : 0.0, 0.0, 0.0), q);
      t += dt;
    }
    return t;
  };
  agents::KickEngine reference(model, gait.walk, gait.kick);
  const double keys = reference.duration();
  EXPECT_NEAR(lasts(gait.kick, 0.0), keys, 1.5 * dt);  // calm throughout
  EXPECT_NEAR(lasts(gait.kick, keys + 0.5), keys + 0.5 + 0.3, 1.5 * dt);
  EXPECT_NEAR(lasts(gait.kick, 100.0), keys + 2.0, 1.5 * dt);  // rocking for good
  agents::KickParameters no_wait = gait.kick;
  no_wait.calm_rate = 0.0;
  EXPECT_NEAR(lasts(no_wait, 100.0), keys, 1.5 * dt);
}

// With both feet down after the swing, a torso tilted beyond tilt_deadband from how it stood at
// the kick's start is moved tilt_gain (m/rad) times the excess towards the raised side, and the
// kick holds the stance while it is tilted (at most calm_wait).
TEST(KickEngine, ATiltedTorsoIsMovedTowardsTheRaisedSide) {
  const robots::RobotModel model = robots::loadRobotModel(test::boosterK1());
  const agents::Gait gait = agents::loadGaitIn(test::sourceDir() / "configs/motions/booster_k1");
  const agents::KickParameters& k = gait.kick;
  ASSERT_GT(k.tilt_gain, 0.0);
  agents::WalkEngine walk(model, gait.walk);  // for its kinematics
  const double dt = 0.01;
  const agents::TorsoTilt start{0.02, -0.05};
  // The left foot's place under the torso (torso frame) after the keyframes' lowering, with
  // the torso tilted by (roll, pitch) then; and how long the kick lasts if it stays so.
  auto after = [&](double roll, double pitch) {
    agents::KickEngine kick(model, gait.walk, k);
    std::vector<double> q = model.pose("stand");
    kick.start(Leg::Right);
    double t = 0.0;
    const double down = k.shift_time + k.lift_time + k.swing_time + k.retract_time + k.lower_time;
    for (; t < down + 0.05; t += dt) kick.update(dt, engine::Vec3::Zero(), q, start);
    const agents::TorsoTilt tilted{start.roll + roll, start.pitch + pitch};
    kick.update(dt, engine::Vec3::Zero(), q, tilted);
    const engine::Vec3 left = feetOf(walk, q).left.translation();
    while (kick.active() && t < 20.0) {
      kick.update(dt, engine::Vec3::Zero(), q, tilted);
      t += dt;
    }
    return std::pair{left, t};
  };
  const auto [upright, upright_lasts] = after(0.0, 0.0);
  // Leaning 0.3 rad right (roll > 0): the torso 0.2 m/rad x 0.22 rad to the left, over the feet.
  const auto [right, right_lasts] = after(0.3, 0.0);
  EXPECT_NEAR(upright.y() - right.y(), k.tilt_gain * (0.3 - k.tilt_deadband), 2e-3);
  EXPECT_NEAR(upright.x() - right.x(), 0.0, 2e-3);
  // Leaning 0.2 rad forwards (pitch > 0): the torso back.
  const auto [forwards, forwards_lasts] = after(0.0, 0.2);
  EXPECT_NEAR(forwards.x() - upright.x(), k.tilt_gain * (0.2 - k.tilt_deadband), 2e-3);
  // Within the deadband: nothing moves.
  const auto [slight, slight_lasts] = after(0.05, -0.05);
  EXPECT_LT((slight - upright).norm(), 1e-6);
  // Held while tilted, up to calm_wait after the keyframes.
  agents::KickEngine reference(model, gait.walk, k);
  EXPECT_NEAR(upright_lasts, reference.duration(), 1.5 * dt);  // calm throughout
  EXPECT_NEAR(slight_lasts, upright_lasts, 1.5 * dt);
  EXPECT_NEAR(right_lasts, reference.duration() + k.calm_wait, 2.5 * dt);
}

TEST(Gait, TheFileSetsTheParametersItNamesAndRefusesUnknownOnes) {
  test::TempDir dir("gait");
  EXPECT_EQ(agents::loadGaitIn(dir.path()).walk.step_period, agents::WalkParameters{}.step_period);
  std::ofstream(dir.path() / "gait.yaml")
      << "walk: {step_period: 0.3, sway: 0.02}\nkick: {reach: 0.2}\n";
  const agents::Gait g = agents::loadGaitIn(dir.path());
  EXPECT_EQ(g.walk.step_period, 0.3);
  EXPECT_EQ(g.walk.sway, 0.02);
  EXPECT_EQ(g.walk.foot_lift, agents::WalkParameters{}.foot_lift);  // not named: the default
  EXPECT_EQ(g.kick.reach, 0.2);
  std::ofstream(dir.path() / "gait.yaml") << "walk: {step_perod: 0.3}\n";
  try {
    agents::loadGaitIn(dir.path());
    ADD_FAILURE() << "an unknown parameter was accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_EQ(e.key(), "walk.step_perod");
    EXPECT_NE(std::string(e.what()).find("unknown parameter"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gait.yaml"), std::string::npos) << e.what();
  }
  std::ofstream(dir.path() / "gait.yaml") << "walk: {step_period: -0.3}\n";
  EXPECT_THROW(agents::loadGaitIn(dir.path()), engine::ConfigError);
  // A share: the gyro smoothing in (0, 1].
  std::ofstream(dir.path() / "gait.yaml") << "walk: {gyro_smoothing: 1}\n";
  EXPECT_EQ(agents::loadGaitIn(dir.path()).walk.gyro_smoothing, 1.0);
  for (const char* bad : {"1.5", "0"}) {
    std::ofstream(dir.path() / "gait.yaml") << "walk: {gyro_smoothing: " << bad << "}\n";
    try {
      agents::loadGaitIn(dir.path());
      ADD_FAILURE() << "gyro_smoothing " << bad << " was accepted";
    } catch (const engine::ConfigError& e) {
      EXPECT_EQ(e.key(), "walk.gyro_smoothing") << e.what();
    }
  }
  // Turning on the spot with smaller steps than walking is refused: it could not keep up.
  std::ofstream(dir.path() / "gait.yaml") << "walk: {max_turn: 0.6, max_turn_on_spot: 0.5}\n";
  try {
    agents::loadGaitIn(dir.path());
    ADD_FAILURE() << "max_turn_on_spot under max_turn was accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_EQ(e.key(), "walk.max_turn_on_spot") << e.what();
  }
  // The Booster K1's gait in the repository loads.
  EXPECT_GT(agents::loadGaitIn(test::sourceDir() / "configs/motions/booster_k1").walk.step_width,
            0.15);
}
