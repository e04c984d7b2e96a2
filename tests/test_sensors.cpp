// Sensors on real Bullet: sonar (batched tracer and Bullet reference), IMU,
// foot pressure, encoders, motor current and temperature, bumpers, noise.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "simsoccer/world/world.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using engine::Pose;
using engine::Vec3;

namespace {

constexpr double kPi = std::numbers::pi;

// One robot at (x, y) facing `yaw`, ball out of the way.
world::Scenario single(double x, double y, double yaw) {
  world::Scenario s = test::scenario(1);
  s.robots[0].x = x;
  s.robots[0].y = y;
  s.robots[0].yaw = yaw;
  s.ball_position = {-4.0, 3.0, -1.0};
  return s;
}

// World pose of a robot's sensor frame.
Pose sensorPose(const world::World& w, world::RobotId r, const char* name) {
  const auto* s = w.robot(r).model->sensor(name);
  return w.linkPose(r, s->link) * s->pose;
}

}  // namespace

TEST(Sonar, NothingInFrontReportsNoEcho) {
  // Whatever the number of rays: the carpet under the cone does not echo
  // back (met too obliquely), nothing else is within range.
  for (const int rays : {9, 32, 128}) {
    world::Scenario sc = single(0.0, 0.0, 0.0);
    sc.sensors.sonar_rays = rays;
    world::World w(sc);
    for (int i = 0; i < 12; ++i) w.stepControlPeriod();
    const auto& f = w.sensorFrame(0);
    const double no_echo = w.robot(0).model->sensor_spec.sonar_no_echo_value;
    for (int s = 0; s < 2; ++s) {
      EXPECT_EQ(f.sonar_echo_count[s], 0) << rays << " rays";
      EXPECT_FLOAT_EQ(f.sonar[s], no_echo);
    }
  }
}

TEST(Sonar, CarpetEchoesWhenTheRobotLeansForward) {
  // Bent 25 deg forward at the hips, the lower rays meet the carpet steeply
  // enough to return: the floor is in the traced scene.
  world::Scenario sc = single(0.0, 0.0, 0.0);
  sc.sensors.sonar_rays = 32;
  world::World w(sc);
  const auto& body = *w.robot(0).model->body;
  for (const char* j : {"LHipPitch", "RHipPitch"})
    w.setJointTarget(0, body.jointIndex(j), -0.9, 1.0);
  for (const char* j : {"LAnklePitch", "RAnklePitch"})
    w.setJointTarget(0, body.jointIndex(j), -0.2, 1.0);
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();
  ASSERT_TRUE(w.isStanding(0));
  const auto& f = w.sensorFrame(0);
  std::printf("leaning: torso pitch %.1f deg, sonar %.3f / %.3f\n", f.angles[1] * 180 / kPi,
              f.sonar[0], f.sonar[1]);
  EXPECT_GT(f.sonar_echo_count[0] + f.sonar_echo_count[1], 0);
  EXPECT_LT(std::min(f.sonar[0], f.sonar[1]), 0.8f);
}

TEST(Sonar, GoalPostAtKnownDistance) {
  // Turn the robot so that the left sonar's axis points at the +x goal's left
  // post, with the post 0.5 m from the sonar.
  const Vec3 post(4.5, 0.8, 0.0);
  const double post_radius = 0.05;
  world::World probe(single(0.0, 0.0, 0.0));
  const auto* sonar = probe.robot(0).model->sensor("SonarLeft");
  const Pose in_torso = probe.linkPose(0, sonar->link) * sonar->pose;  // at yaw 0, torso at (0,0)
  const Pose torso0 = probe.torsoPose(0);
  const Vec3 offset = torso0.inverse() * in_torso.translation();  // sonar in torso frame
  const Vec3 axis = (torso0.linear().transpose() * in_torso.linear().col(0));
  const double axis_yaw = std::atan2(axis.y(), axis.x());
  for (const double distance : {0.35, 0.5, 0.7}) {
    const double yaw = -axis_yaw;  // the axis points along +x, at the post, from the field
    const double horizontal = distance + post_radius;
    const Eigen::Rotation2Dd rot(yaw);
    const Eigen::Vector2d sonar_xy = post.head<2>() - Eigen::Vector2d(horizontal, 0.0);
    const Eigen::Vector2d torso_xy = sonar_xy - rot * offset.head<2>();
    world::World w(single(torso_xy.x(), torso_xy.y(), yaw));
    w.stepControlPeriod();
    // Geometric truth: horizontal distance from the sonar to the post's surface.
    const Vec3 o = sensorPose(w, 0, "SonarLeft").translation();
    const double truth = (post.head<2>() - o.head<2>()).norm() - post_radius;
    const auto& f = w.sensorFrame(0);
    std::printf("post at %.2f m: sonar left %.4f m, truth %.4f m\n", distance, f.sonar[0], truth);
    EXPECT_NEAR(f.sonar[0], truth, 0.01);
  }
}

TEST(Sonar, RobotInFrontAtKnownDistance) {
  // Robot B stands so that the centre of its upper torso sphere lies on
  // robot A's left sonar axis, 0.45 m away.
  world::World probe(single(0.0, 0.0, 0.0));
  const Pose sonar = sensorPose(probe, 0, "SonarLeft");
  const Vec3 axis = sonar.linear().col(0);
  const double upper_radius = 0.0642;
  const Vec3 upper_in_torso(0.0019, 0.0, 0.056);
  const double centre_distance = 0.45 + upper_radius;
  const Vec3 target = sonar.translation() + centre_distance * axis;
  // B faces A; its torso origin is below and behind the sphere centre.
  world::Scenario s = single(0.0, 0.0, 0.0);
  world::RobotPlacement b;
  b.team = 1;
  b.number = 1;
  b.yaw = kPi;
  b.x = target.x() + upper_in_torso.x();
  b.y = target.y();
  s.robots.push_back(b);
  world::World w(s);
  // Vertical offset: compare against the real sphere centre after placement.
  w.stepControlPeriod();
  const Pose tb = w.torsoPose(1);
  const Vec3 centre = tb * upper_in_torso;
  const Vec3 o = sensorPose(w, 0, "SonarLeft").translation();
  const Vec3 dir = sensorPose(w, 0, "SonarLeft").linear().col(0);
  // Truth: the nearest point of that sphere to the sonar (along the axis when
  // the centre is on it; otherwise the ray closest to it sees a bit farther).
  const double truth = (centre - o).norm() - upper_radius;
  const double off_axis = std::acos(std::clamp(dir.dot((centre - o).normalized()), -1.0, 1.0));
  const auto& f = w.sensorFrame(0);
  std::printf(
      "robot ahead: sonar left %.4f m, truth %.4f m (centre %.1f deg off axis), echoes %d\n",
      f.sonar[0], truth, off_axis * 180 / kPi, f.sonar_echo_count[0]);
  EXPECT_NEAR(f.sonar[0], truth, 0.01);
}

TEST(Sonar, ObjectJustOutsideTheConeIsNotSeen) {
  // The ball floats (no gravity) at 0.5 m from the left sonar, off its axis
  // in the sonar's horizontal plane: seen inside the 60 deg cone, not just
  // outside it. 64 rays so the ball cannot slip between them.
  for (const auto& [off_axis_deg, seen] : {std::pair{20.0, true}, std::pair{38.0, false}}) {
    world::Scenario s = single(0.0, 0.0, 0.0);
    s.physics.gravity = 0.0;
    s.sensors.sonar_rays = 64;
    world::World probe(s);
    const Pose sonar = sensorPose(probe, 0, "SonarLeft");
    const double a = off_axis_deg * kPi / 180.0;
    const Vec3 local(std::cos(a), std::sin(a), 0.0);  // ball edge is 5.7 deg nearer the axis
    s.ball_position = sonar * (0.5 * local);
    world::World w(s);
    w.stepControlPeriod();
    const auto& f = w.sensorFrame(0);
    std::printf("ball %.0f deg off axis: left sonar %.3f (%d echoes)\n", off_axis_deg, f.sonar[0],
                f.sonar_echo_count[0]);
    // Farther echoes are the carpet under the cone's lower rays.
    bool ball = false;
    for (int e = 0; e < f.sonar_echo_count[0]; ++e)
      ball = ball || std::abs(f.sonar_echoes[0][e] - 0.45) < 0.01;
    EXPECT_EQ(ball, seen);
  }
}

TEST(Sonar, NeverSeesItsOwnRobot) {
  // Arms raised straight ahead cross both sonar cones 0.1-0.25 m out.
  world::World w(single(0.0, 0.0, 0.0));
  const auto& body = *w.robot(0).model->body;
  for (const char* j : {"LShoulderPitch", "RShoulderPitch"})
    w.setJointTarget(0, body.jointIndex(j), 0.0, 1.0);
  for (int i = 0; i < 60; ++i) w.stepControlPeriod();
  ASSERT_TRUE(w.isStanding(0));
  std::vector<engine::RayHit> batched, reference;
  w.sensors().traceBatched(w.physics(), batched);
  w.sensors().traceReference(w.physics(), reference);
  const auto& rays = w.sensors().buildSonarRays(w.physics());
  int arm_rays = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    // Only the carpet, far below, may echo; never the robot's own links.
    EXPECT_TRUE(batched[i].object == engine::kNoObject || batched[i].object < 1000) << i;
    EXPECT_FALSE(batched[i].distance < 0.5f) << i;
    EXPECT_FALSE(reference[i].distance < 0.5f) << i;
    // Without the exclusion the same ray would stop on an arm.
    const double unexcluded = w.physics().rayTestClosest(
        rays[i].origin.cast<double>(), rays[i].direction.cast<double>(), rays[i].max_distance, -1);
    arm_rays += unexcluded < 0.3;
  }
  EXPECT_GT(arm_rays, 0);
  const auto& f = w.sensorFrame(0);
  for (int s = 0; s < 2; ++s) EXPECT_GT(f.sonar[s], 0.5f);
}

// The sonar scene holds only the robots another robot's sonar can reach
// (0.8 m of range plus the robot's own reach): two robots face to face, four
// more in the field's corners, 3.9 m and more from every other. The echoes are the same as
// Bullet's, which has every robot.
TEST(Sonar, RobotsOutOfEverySonarsReachAreLeftOutWithTheSameEchoes) {
  world::Scenario s = single(0.0, 0.0, 0.0);
  s.sensors.sonar_rays = 32;
  world::RobotPlacement facing{1, 1, 0.55, 0.05, kPi, "stand", ""};
  s.robots.push_back(facing);
  const double far[4][2] = {{-3.0, 2.5}, {-3.0, -2.5}, {3.0, 2.5}, {3.0, -2.5}};
  for (int i = 0; i < 4; ++i)
    s.robots.push_back({1, i + 2, far[i][0], far[i][1], 0.0, "stand", ""});
  world::World w(s);
  for (int i = 0; i < 20; ++i) w.stepControlPeriod();
  std::vector<engine::RayHit> batched, reference;
  w.sensors().traceBatched(w.physics(), batched);
  w.sensors().traceReference(w.physics(), reference);
  ASSERT_EQ(batched.size(), 6u * 2u * 32u);
  int robot_hits = 0;
  for (size_t i = 0; i < batched.size(); ++i) {
    ASSERT_EQ(std::isfinite(batched[i].distance), std::isfinite(reference[i].distance)) << i;
    if (!std::isfinite(batched[i].distance)) continue;
    // Bullet's rounded margins: 1.1 mm off the surface, up to 7 mm along a grazing ray.
    EXPECT_NEAR(batched[i].distance, reference[i].distance, 0.007) << i;
    robot_hits += batched[i].object >= 1000;
  }
  EXPECT_GT(robot_hits, 10);  // the two facing robots see each other
  // The scene: the ball, the goals and two robots' shapes, not six.
  world::World alone(single(0.0, 0.0, 0.0));
  std::vector<engine::RayHit> unused;
  alone.sensors().traceBatched(alone.physics(), unused);
  const size_t without_robots = alone.sensors().sonarScene().primitiveCount();  // it sees no one
  world::Scenario pair = s;
  pair.robots.resize(2);
  world::World two(pair);
  two.sensors().traceBatched(two.physics(), unused);
  const size_t per_robot = (two.sensors().sonarScene().primitiveCount() - without_robots) / 2;
  ASSERT_GT(per_robot, 10u);
  EXPECT_EQ(w.sensors().sonarScene().primitiveCount(), without_robots + 2 * per_robot);
}

TEST(Sonar, BatchedAndReferenceTracersAgreeOnRandomScene) {
  // 22 robots packed into 4 x 3 m with random headings and postures, so that
  // many rays hit robots, the ball, the goal or the carpet.
  engine::NormalSampler rng(2024);
  world::Scenario s = test::scenario(0);
  s.field_file = test::splField();
  s.sensors.sonar_rays = 32;
  s.ball_position = {2.9, 0.1, -1.0};
  for (int i = 0; i < 22; ++i) {
    world::RobotPlacement p;
    p.team = i % 2;
    p.number = i / 2 + 1;
    p.x = 1.2 + 0.55 * (i % 6) + 0.05 * rng();
    p.y = -1.5 + 0.75 * (i / 6) + 0.05 * rng();
    p.yaw = kPi * rng();
    s.robots.push_back(p);
  }
  world::World w(s);
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    const auto& body = *w.robot(r).model->body;
    for (const char* j : {"LShoulderPitch", "RShoulderPitch", "HeadYaw"})
      w.setJointTarget(r, body.jointIndex(j), 0.8 * rng(), 1.0);
  }
  for (int i = 0; i < 30; ++i) w.stepControlPeriod();
  std::vector<engine::RayHit> batched, reference;
  w.sensors().traceBatched(w.physics(), batched);
  w.sensors().traceReference(w.physics(), reference);
  ASSERT_EQ(batched.size(), 22u * 2u * 32u);
  int hits = 0, robot_hits = 0, grazing = 0;
  double worst = 0.0, worst_along = 0.0, worst_frontal = 0.0;
  const auto& rays = w.sensors().buildSonarRays(w.physics());
  for (size_t i = 0; i < batched.size(); ++i) {
    const bool a = std::isfinite(batched[i].distance), b = std::isfinite(reference[i].distance);
    // Right at the end of the range one tracer may stop a hair short of the
    // other (Bullet's collision margins round edges by up to 4 mm).
    const double range = 0.8, edge = 0.001;
    if (a != b && std::min(batched[i].distance, reference[i].distance) > range - edge) continue;
    // A ray that grazes a surface (within 75 degrees of parallel to it) may
    // pass inside Bullet's rounded margin and just outside the exact shape:
    // a hit for one tracer only. Allowed for a few rays, counted.
    if (a != b && b) {
      Vec3 n;
      const auto& ray = rays[i];
      w.physics().rayTestClosest(ray.origin.cast<double>(), ray.direction.cast<double>(),
                                 ray.max_distance, ray.exclude_owner, &n);
      if (std::abs(n.dot(ray.direction.cast<double>())) < 0.26) {
        ++grazing;
        continue;
      }
    }
    ASSERT_EQ(a, b) << "ray " << i << ": batched " << batched[i].distance << " (object "
                    << batched[i].object << "), reference " << reference[i].distance;
    if (!a) continue;
    ++hits;
    robot_hits += batched[i].object >= 1000;
    // Bullet's convex cast stops once its point is within 1 mm of the shape,
    // so its error is that far from the surface, measured along the surface
    // normal; along the ray it grows as 1 / cos(incidence) on grazing hits.
    // The incidence is taken from Bullet's own hit normal.
    Vec3 normal;
    w.physics().rayTestClosest(rays[i].origin.cast<double>(), rays[i].direction.cast<double>(),
                               rays[i].max_distance, rays[i].exclude_owner, &normal);
    const double along = std::abs(batched[i].distance - reference[i].distance);
    const double incidence_cos = std::abs(normal.dot(rays[i].direction.cast<double>()));
    // On an edge (grazing, or the two hit points within 2 mm), each tracer may
    // meet a different face of it, or Bullet the margin's rounding between them.
    if (batched[i].normal.cast<double>().dot(normal) < 0.9 &&
        (incidence_cos < 0.26 || along < 0.002)) {
      ++grazing;
      continue;
    }
    EXPECT_GT(batched[i].normal.cast<double>().dot(normal), 0.9) << "normals disagree, ray " << i;
    worst = std::max(worst, along * incidence_cos);
    worst_along = std::max(worst_along, along);
    if (incidence_cos > 0.5) worst_frontal = std::max(worst_frontal, along);
  }
  std::printf(
      "%zu rays, %d hits (%d on robots); largest difference from the surface %.5f m, "
      "along the ray %.5f m (%.5f m within 60 deg of the normal); %d grazing or edge rays "
      "where they disagree (left out)\n",
      batched.size(), hits, robot_hits, worst, worst_along, worst_frontal, grazing);
  EXPECT_GT(robot_hits, 100);
  // A few: at most 1 % of the rays (the scene's postures decide how many graze).
  EXPECT_LE(grazing, static_cast<int>(batched.size() / 100))
      << "grazing or edge rays where the tracers disagree";
  // Bullet's GJK cast terminates 1 mm from the shape (plus float error).
  EXPECT_LT(worst, 0.0015);
  EXPECT_LT(worst_frontal, 0.002);
}

TEST(Imu, StandingStill) {
  world::World w(single(0.0, 0.0, 0.3));
  // 6 s: the sway after placement has died out (a slow pitch oscillation of
  // the servo-held stance, 0.03 rad/s at 1.5 s, below 0.003 from 5 s on).
  for (int i = 0; i < 600; ++i) w.stepControlPeriod();
  const auto& f = w.sensorFrame(0);
  // The accelerometer reads gravity's reaction (+9.81 up) in the torso frame.
  // The standing torso leans a little (the legs' servos sag under the
  // weight: about 0.4 deg), so the reading is compared with gravity in that
  // frame, and with (0, 0, 9.81) up to the lean.
  const engine::Mat3 rt = w.torsoPose(0).linear().transpose();
  const Vec3 expected = rt * Vec3(0, 0, 9.81);
  const double lean = std::acos(std::clamp(w.torsoPose(0).linear()(2, 2), -1.0, 1.0));
  std::printf("accelerometer (%.4f, %.4f, %.4f), torso lean %.2f deg\n", f.accelerometer[0],
              f.accelerometer[1], f.accelerometer[2], lean * 180 / kPi);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(f.accelerometer[k], expected[k], 0.05) << k;
  EXPECT_NEAR(f.accelerometer[2], 9.81, 0.05);
  EXPECT_NEAR(Vec3(f.accelerometer[0], f.accelerometer[1], f.accelerometer[2]).norm(), 9.81, 0.05);
  EXPECT_LT(lean, 0.5 * kPi / 180);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(f.gyroscope[k], 0.0, 0.005) << k;
  EXPECT_NEAR(f.angles[2], 0.3, 0.01);  // yaw: the placement heading
}

TEST(Imu, GyroMatchesKnownRotationRate) {
  world::Scenario s = single(0.0, 0.0, 0.0);
  s.physics.gravity = 0.0;
  world::World w(s);
  // Lift it off the carpet, tilt and turn it, and spin it about the world
  // z and x axes: torso and world frames differ a lot.
  Pose lifted = w.torsoPose(0);
  lifted.translation().z() += 1.0;
  lifted.linear() = (Eigen::AngleAxisd(1.0, Vec3::UnitZ()) * Eigen::AngleAxisd(0.6, Vec3::UnitY()) *
                     Eigen::AngleAxisd(-0.4, Vec3::UnitX()))
                        .toRotationMatrix();
  std::vector<double> q = w.robot(0).model->pose("stand");
  w.physics().resetArticulation(w.robot(0).body, lifted, q);
  const Vec3 rate(0.4, 0.0, 1.5);
  w.physics().setRootVelocity(w.robot(0).body, Vec3::Zero(), rate);
  w.stepControlPeriod();
  w.stepControlPeriod();
  const auto& f = w.sensorFrame(0);
  const Vec3 expected = w.torsoPose(0).linear().transpose() * rate;  // in the torso frame
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(f.gyroscope[k], expected[k], 0.02) << k;
  EXPECT_GT((expected - rate).norm(), 0.5);  // the frames really differ
  // Free fall / weightless: the accelerometer reads (almost) no specific force
  // beyond the centripetal term at its offset from the centre of mass.
  EXPECT_LT(Vec3(f.accelerometer[0], f.accelerometer[1], f.accelerometer[2]).norm(), 0.5);
}

TEST(Imu, FreeFallReadsNoSpecificForce) {
  // With gravity on, lifted 3 m above the carpet and let go (limp): the
  // accelerometer reads ~0 while falling, then gravity's reaction at rest.
  world::World w(single(0.0, 0.0, 0.0));
  Pose lifted = w.torsoPose(0);
  lifted.translation().z() += 3.0;
  w.physics().resetArticulation(w.robot(0).body, lifted, w.robot(0).model->pose("stand"));
  for (int i = 0; i < 10; ++i) w.stepControlPeriod();  // 0.1 s of falling
  const auto& f = w.sensorFrame(0);
  const Vec3 falling(f.accelerometer[0], f.accelerometer[1], f.accelerometer[2]);
  std::printf("free fall: accelerometer |%.4f| m/s^2\n", falling.norm());
  EXPECT_LT(falling.norm(), 0.1);
}

TEST(Imu, TiltedPlacementAngles) {
  world::Scenario s = single(0.0, 0.0, 0.0);
  s.physics.gravity = 0.0;
  world::World w(s);
  const double roll = 0.2, pitch = -0.3, yaw = 0.5;
  Pose tilted = Pose::Identity();
  tilted.translation() = Vec3(0, 0, 1.0);
  tilted.linear() =
      (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
       Eigen::AngleAxisd(roll, Vec3::UnitX()))
          .toRotationMatrix();
  w.physics().resetArticulation(w.robot(0).body, tilted, w.robot(0).model->pose("stand"));
  w.stepControlPeriod();
  const auto& f = w.sensorFrame(0);
  EXPECT_NEAR(f.angles[0], roll, 0.005);
  EXPECT_NEAR(f.angles[1], pitch, 0.005);
  EXPECT_NEAR(f.angles[2], yaw, 0.005);
}

TEST(Fsr, StandingRobotWeighsItsWeight) {
  world::World w(single(0.0, 0.0, 0.0));
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();
  const auto& f = w.sensorFrame(0);
  const double weight = w.robot(0).model->body->totalMass() * 9.81;
  double total = 0.0;
  for (float v : f.fsr) total += v;
  std::printf("FSR total %.2f N (weight %.2f N), left %.2f right %.2f\n", total, weight,
              f.foot_weight[0], f.foot_weight[1]);
  EXPECT_NEAR(total, weight, 0.03 * weight);
  EXPECT_NEAR(f.foot_weight[0], 0.5 * weight, 0.1 * weight);
  EXPECT_NEAR(f.foot_weight[1], 0.5 * weight, 0.1 * weight);
  EXPECT_NEAR(f.foot_weight[0] + f.foot_weight[1], total, 1e-3 * weight);
  for (size_t k = 0; k < world::kFsrs; ++k) EXPECT_NEAR(f.fsr_kg[k], f.fsr[k] / 9.81, 1e-4);
}

TEST(Fsr, LeaningForwardMovesCentreOfPressureForward) {
  world::World w(single(0.0, 0.0, 0.0));
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();
  const float before = w.sensorFrame(0).centre_of_pressure[0][0];
  const auto& body = *w.robot(0).model->body;
  // Bend forward at the hips (CoM moves forward over the feet).
  w.setJointTarget(0, body.jointIndex("LHipPitch"), -0.65, 1.0);
  w.setJointTarget(0, body.jointIndex("RHipPitch"), -0.65, 1.0);
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();
  const auto& f = w.sensorFrame(0);
  std::printf("centre of pressure x: %.4f -> %.4f m\n", before, f.centre_of_pressure[0][0]);
  EXPECT_GT(f.centre_of_pressure[0][0], before + 0.01);
  EXPECT_GT(f.centre_of_pressure[1][0], before + 0.01);
  EXPECT_TRUE(w.isStanding(0));
}

TEST(Fsr, FrontSensorsCarryALeanForward) {
  world::World w(single(0.0, 0.0, 0.0));
  const auto& body = *w.robot(0).model->body;
  for (const char* j : {"LHipPitch", "RHipPitch"})
    w.setJointTarget(0, body.jointIndex(j), -0.65, 1.0);
  for (int i = 0; i < 150; ++i) w.stepControlPeriod();
  ASSERT_TRUE(w.isStanding(0));
  const auto& f = w.sensorFrame(0);
  for (int foot = 0; foot < 2; ++foot) {
    const size_t b = static_cast<size_t>(4 * foot);
    EXPECT_GT(f.fsr[b + 0] + f.fsr[b + 1], f.fsr[b + 2] + f.fsr[b + 3]) << foot;  // FL+FR > RL+RR
  }
}

TEST(Fsr, BilinearWeightsOrderAndEdges) {
  const engine::FsrRectangle r{0.07, -0.03, 0.03, -0.02};  // front, rear, left, right
  auto w = engine::fsrWeights(r, 0.07, 0.03);              // on the front-left sensor
  EXPECT_DOUBLE_EQ(w[0], 1.0);
  w = engine::fsrWeights(r, 0.07, -0.02);  // front-right
  EXPECT_DOUBLE_EQ(w[1], 1.0);
  w = engine::fsrWeights(r, -0.03, 0.03);  // rear-left
  EXPECT_DOUBLE_EQ(w[2], 1.0);
  w = engine::fsrWeights(r, -0.03, -0.02);  // rear-right
  EXPECT_DOUBLE_EQ(w[3], 1.0);
  w = engine::fsrWeights(r, 0.02, 0.005);  // the middle
  for (double x : w) EXPECT_NEAR(x, 0.25, 1e-12);
  w = engine::fsrWeights(r, 0.02, 0.2);  // beyond the left edge: the left pair, halved
  EXPECT_NEAR(w[0], 0.5, 1e-12);
  EXPECT_NEAR(w[2], 0.5, 1e-12);
  w = engine::fsrWeights(r, 0.045, -0.0075);  // 3/4 front, 1/4 left
  EXPECT_NEAR(w[0], 0.75 * 0.25, 1e-12);
  EXPECT_NEAR(w[1], 0.75 * 0.75, 1e-12);
  EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 1.0, 1e-12);
}

TEST(Fsr, SwayRightLoadsTheRightFootAndTheRightSensors) {
  // Both hip rolls +, ankle rolls -: the feet move left relative to the
  // hips, so the torso moves right over the right foot. Compared with
  // standing, the right foot carries more, and within it the right-hand
  // sensors (FR, RR) take a larger share. Read once the stance has settled:
  // the weight swings from foot to foot for seconds after the targets change
  // (at 5 ms the right foot carried 32 N after 1.5 s, 28 N from 3 s on; at a
  // 10 ms step, better damped, 27.7 and 27.4), so an early reading is a phase
  // of that swing.
  auto frame = [](double roll) {
    world::World w(single(0.0, 0.0, 0.0));
    const auto& body = *w.robot(0).model->body;
    for (const char* j : {"LHipRoll", "RHipRoll"})
      w.setJointTarget(0, body.jointIndex(j), roll, 1.0);
    for (const char* j : {"LAnkleRoll", "RAnkleRoll"})
      w.setJointTarget(0, body.jointIndex(j), -roll, 1.0);
    for (int i = 0; i < 300; ++i) w.stepControlPeriod();
    EXPECT_TRUE(w.isStanding(0));
    return w.sensorFrame(0);
  };
  const auto stand = frame(0.0), sway = frame(0.08);
  auto right_share = [](const world::SensorFrame& f, size_t foot) {
    return (f.fsr[4 * foot + 1] + f.fsr[4 * foot + 3]) / f.foot_weight[foot];
  };
  std::printf(
      "right foot weight %.1f -> %.1f N; right-sensor share L %.2f -> %.2f, R %.2f -> %.2f\n",
      stand.foot_weight[1], sway.foot_weight[1], right_share(stand, 0), right_share(sway, 0),
      right_share(stand, 1), right_share(sway, 1));
  EXPECT_GT(sway.foot_weight[1], stand.foot_weight[1] + 1.0);
  EXPECT_GT(right_share(sway, 1), right_share(stand, 1));
  EXPECT_LT(sway.centre_of_pressure[1][1], stand.centre_of_pressure[1][1]);
}

TEST(Joints, EncoderQuantisation) {
  world::World w(single(0.0, 0.0, 0.0));
  for (int i = 0; i < 10; ++i) w.stepControlPeriod();
  const auto& f = w.sensorFrame(0);
  const double lsb = 2 * kPi / 4096.0;  // 12-bit encoder
  for (size_t a = 0; a < 23; ++a) {
    const double counts = f.position[a] / lsb;
    EXPECT_NEAR(counts, std::round(counts), 1e-3) << a;
  }
  const int knee = w.robot(0).model->body->jointIndex("LKneePitch");
  EXPECT_NEAR(f.position[10], w.jointPosition(0, knee), 0.5 * lsb + 1e-6);
}

TEST(Joints, CurrentRisesWithLoadAndTemperatureWithTime) {
  // Knees: standing (loaded) against floating (unloaded), 60 s each.
  auto run = [](double gravity, double knee) {
    world::Scenario s = single(0.0, 0.0, 0.0);
    s.physics.gravity = gravity;
    world::World w(s);
    const auto& body = *w.robot(0).model->body;
    for (const char* side : {"L", "R"}) {
      w.setJointTarget(0, body.jointIndex(std::string(side) + "KneePitch"), knee, 1.0);
      w.setJointTarget(0, body.jointIndex(std::string(side) + "HipPitch"), -knee / 2, 1.0);
      w.setJointTarget(0, body.jointIndex(std::string(side) + "AnklePitch"), -knee / 2, 1.0);
    }
    for (int i = 0; i < 6000; ++i) w.stepControlPeriod();
    return w.sensorFrame(0);
  };
  const auto floating = run(0.0, 0.9);
  const auto standing = run(-9.81, 0.9);
  const auto squatting = run(-9.81, 1.6);
  std::printf(
      "knee current: floating %.3f A, standing %.3f A, squatting %.3f A; "
      "temperature %.2f / %.2f / %.2f C\n",
      floating.current[10], standing.current[10], squatting.current[10], floating.temperature[10],
      standing.temperature[10], squatting.temperature[10]);
  EXPECT_LT(floating.current[10], standing.current[10]);
  EXPECT_LT(standing.current[10], squatting.current[10]);
  EXPECT_NEAR(floating.temperature[10], 25.0, 0.2);
  EXPECT_GT(squatting.temperature[10], standing.temperature[10]);
  EXPECT_GT(squatting.temperature[10], 25.5);
}

TEST(Touch, BumperFiresWhenTheToeHitsAGoalPost) {
  // The robot faces the +x goal's left post with its left toe about a
  // millimetre away and is shoved forward into it, hard enough that its feet
  // slide on the carpet (at 0.4 m/s they slid 1 mm at a 5 ms step and held at
  // 10 ms, the toe 0.2 mm short of the post).
  const double toe = 0.1025;  // foot box front face ahead of the ankle
  world::World probe(single(0.0, 0.0, 0.0));
  const Vec3 lfoot =
      probe.torsoPose(0).inverse() *
      probe.linkPose(0, probe.robot(0).model->body->linkIndex("LFoot")).translation();
  const double x = 4.5 - 0.05 - 0.005 - toe - lfoot.x();
  const double y = 0.8 - lfoot.y() - 0.0075;
  world::World w(single(x, y, 0.0));
  w.physics().setRootVelocity(w.robot(0).body, Vec3(0.6, 0, 0), Vec3::Zero());
  bool left = false, right_foot = false;
  for (int i = 0; i < 50; ++i) {
    w.stepControlPeriod();
    const auto& f = w.sensorFrame(0);
    left = left || f.touch[static_cast<size_t>(world::Touch::LFootBumperLeft)] ||
           f.touch[static_cast<size_t>(world::Touch::LFootBumperRight)];
    right_foot = right_foot || f.touch[static_cast<size_t>(world::Touch::RFootBumperLeft)] ||
                 f.touch[static_cast<size_t>(world::Touch::RFootBumperRight)];
  }
  EXPECT_TRUE(left);
  EXPECT_FALSE(right_foot);
}

TEST(Touch, ButtonsAreInputs) {
  world::World w(single(0.0, 0.0, 0.0));
  w.setTouch(0, world::Touch::ChestButton, true);
  w.stepControlPeriod();
  EXPECT_EQ(w.sensorFrame(0).touch[0], 1);
  EXPECT_EQ(w.sensorFrame(0).touch[1], 0);
  EXPECT_THROW(w.setTouch(0, world::Touch::LFootBumperLeft, true), std::invalid_argument);
}

TEST(Noise, SameSeedSameStreamDifferentSeedDifferent) {
  auto stream = [](uint64_t seed) {
    world::Scenario s = single(0.0, 0.0, 0.0);
    s.seed = seed;
    s.sensors.gyro_noise = Vec3(0.01, 0.01, 0.01);
    s.sensors.accel_noise = Vec3(0.05, 0.05, 0.05);
    s.sensors.angle_noise = Vec3(0.002, 0.002, 0.002);
    world::World w(s);
    std::vector<float> out;
    for (int i = 0; i < 50; ++i) {
      w.stepControlPeriod();
      const auto& f = w.sensorFrame(0);
      out.insert(out.end(), f.accelerometer.begin(), f.accelerometer.end());
      out.insert(out.end(), f.gyroscope.begin(), f.gyroscope.end());
      out.insert(out.end(), f.angles.begin(), f.angles.end());
    }
    return out;
  };
  const auto a = stream(5), b = stream(5), c = stream(6);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  // The noise is there: the gyro of a still robot varies.
  double spread = 0;
  for (size_t i = 3; i < a.size(); i += 9)
    spread = std::max(spread, std::abs(static_cast<double>(a[i])));
  EXPECT_GT(spread, 0.005);
}

TEST(SensorFrame, StampedWithSimulationTime) {
  world::World w(single(0.0, 0.0, 0.0));
  for (int i = 0; i < 7; ++i) w.stepControlPeriod();
  EXPECT_EQ(w.sensorFrame(0).tick, 7u);
  EXPECT_NEAR(w.sensorFrame(0).time, 0.07, 1e-12);
}

// A referee places robots after the step: the frame the agents read next describes the robot
// as placed (encoders, IMU angles and the accelerometer at rest), not where it was a moment ago.
TEST(Sensors, TheFrameDescribesARobotAsPlaced) {
  world::World w(test::scenario(1));
  for (int i = 0; i < 50; ++i) w.stepControlPeriod();
  const robots::RobotModel& model = *w.robot(0).model;
  engine::Pose lying = engine::Pose::Identity();
  lying.linear() = Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                   Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  lying.translation() = Eigen::Vector3d(1.0, 2.0, 0.2);
  w.placeRobot(0, lying, "stand");
  const world::SensorFrame& f = w.sensorFrame(0);
  EXPECT_NEAR(f.angles[1], M_PI / 2, 1e-3);  // on its front
  EXPECT_NEAR(f.accelerometer[0], -9.81, 0.05);
  EXPECT_NEAR(f.accelerometer[2], 0.0, 0.05);
  w.placeRobot(0, 1.0, 2.0, 0.8);  // upright, in the stand pose
  EXPECT_NEAR(f.angles[0], 0.0, 1e-3);
  EXPECT_NEAR(f.angles[1], 0.0, 1e-3);
  EXPECT_NEAR(f.angles[2], 0.8, 1e-3);
  EXPECT_NEAR(f.accelerometer[2], 9.81, 0.05);
  const double resolution =
      2.0 * std::numbers::pi / static_cast<double>(1 << model.sensor_spec.encoder_bits);
  const std::vector<double>& stand = model.pose("stand");
  for (size_t a = 0; a < model.actuators.size(); ++a) {
    if (model.actuators[a].kind != robots::Actuator::Kind::Joint) continue;
    EXPECT_NEAR(f.position[a], stand[static_cast<size_t>(model.actuators[a].index)], resolution)
        << a;
    EXPECT_EQ(f.velocity[a], 0.0f) << a;
  }
  for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(f.gyroscope[k], 0.0, 0.02);
}
