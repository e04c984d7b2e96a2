// The Nao models: data loaded from YAML against the reference, and the
// Bullet multibody built from it (real Bullet).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "simsoccer/engine/physics_world.hpp"
#include "simsoccer/protocol/wire.hpp"
#include "simsoccer/robots/robot_model.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using engine::Vec3;

namespace {

// Joint placement in a floating, gravity-free world, so nothing moves.
struct FloatingRobot {
  engine::PhysicsWorld physics{[] {
    engine::PhysicsSettings s;
    s.gravity = Vec3::Zero();
    return s;
  }()};
  engine::ArticulationId id;
  explicit FloatingRobot(const robots::RobotModel& model, const std::vector<double>& q) {
    engine::Pose root = engine::Pose::Identity();
    root.translation() = Vec3(0, 0, 1.0);
    id = physics.addArticulation(model.body, root, q, 0);
  }
};

}  // namespace

TEST(RobotModel, H25TotalMassMatchesReferenceSum) {
  const auto nao = robots::loadRobotModel(test::naoH25());
  // nao.md 1: sum of the V6 URDF link masses 5.360 kg (fingers massless).
  EXPECT_NEAR(nao.body->totalMass(), 5.360, 0.01 * 5.360);
  EXPECT_EQ(nao.body->links.size(), 25u);  // torso + 24 hinge links
  EXPECT_EQ(nao.body->joints.size(), 24u);
  EXPECT_EQ(nao.actuators.size(), 25u);  // LoLA arrays
  EXPECT_EQ(nao.hands.size(), 2u);
}

// The Nao description's actuator list is the command order of the protocol
// (LoLA's), entry for entry: agents index commands by protocol::kNaoActuatorOrder.
TEST(RobotModel, H25ActuatorsAreInTheProtocolsOrder) {
  const auto nao = robots::loadRobotModel(test::naoH25());
  ASSERT_EQ(nao.actuators.size(), protocol::kActuators);
  for (size_t a = 0; a < protocol::kActuators; ++a)
    EXPECT_EQ(nao.actuators[a].name, protocol::kNaoActuatorOrder[a]) << "entry " << a;
}

// Which servos are implicit depends on the step: the leg pitch motors at
// any step, the other leg and the arm motors above 5 ms (their explicit servo
// was measured stable up to it), the head, wrists and hands never.
TEST(RobotModel, H25ServosImplicitWhereTheirExplicitServoIsNotStable) {
  const auto nao = robots::loadRobotModel(test::naoH25());
  auto motor = [&](const std::string& name) -> const engine::Motor& {
    for (const engine::Motor& m : nao.body->motors)
      if (m.name == name) return m;
    throw std::runtime_error("no motor " + name);
  };
  for (const char* name : {"leg_pitch"}) {
    EXPECT_TRUE(motor(name).implicitAt(0.003)) << name;
    EXPECT_TRUE(motor(name).implicitAt(0.010)) << name;
  }
  for (const char* name : {"leg_yaw_roll", "shoulder_pitch", "arm_yaw", "arm_roll"}) {
    EXPECT_FALSE(motor(name).implicitAt(0.005)) << name;
    EXPECT_TRUE(motor(name).implicitAt(0.010)) << name;
  }
  for (const char* name : {"head_yaw", "head_pitch", "wrist", "hand"})
    EXPECT_FALSE(motor(name).implicitAt(0.010)) << name;
}

TEST(RobotModel, H21TotalMassMatchesReference) {
  const auto nao = robots::loadRobotModel(test::naoH21());
  EXPECT_NEAR(nao.body->totalMass(), 5.029, 0.01 * 5.029);  // nao.md 1: H21 (V4) 5.029 kg
  EXPECT_EQ(nao.body->joints.size(), 22u);                  // 21 DOF + the mimic RHipYawPitch hinge
  EXPECT_EQ(nao.body->jointIndex("LWristYaw"), -1);
  EXPECT_EQ(nao.actuators.size(), 25u);
  EXPECT_EQ(nao.actuators[static_cast<size_t>(nao.actuatorIndex("LHand"))].kind,
            robots::Actuator::Kind::Absent);
}

// Rubber soles, plastic shells: on the carpet (friction 1.6 in Bullet's
// product rule) the soles hold at 0.625 x 1.6 = 1.0 and the shells at 0.88,
// while robots in contact slide off each other (0.55 x 0.55 = 0.3).
TEST(RobotModel, FeetHaveRubberSolesTheRestPlastic) {
  for (const auto& file : {test::naoH25(), test::naoH21()}) {
    const auto nao = robots::loadRobotModel(file);
    EXPECT_DOUBLE_EQ(nao.body->material.friction, 0.55) << file;
    for (const auto& link : nao.body->links) {
      const bool foot = link.name == "LFoot" || link.name == "RFoot";
      ASSERT_EQ(link.material.has_value(), foot) << file << " " << link.name;
      if (foot) {
        EXPECT_DOUBLE_EQ(link.material->friction, 0.625);
      }
    }
  }
}

TEST(RobotModel, ZeroPoseSoleToTorsoHeight) {
  for (const auto& file : {test::naoH25(), test::naoH21()}) {
    const auto nao = robots::loadRobotModel(file);
    const std::vector<double> zero(nao.body->joints.size(), 0.0);
    // nao.md 1: 85 + 100 + 102.9 + 45.19 = 333.09 mm.
    EXPECT_NEAR(nao.soleDepth(zero), 0.33309, 0.001) << file;
    // The same through Bullet: the left foot's joint frame and its sole face.
    FloatingRobot robot(nao, zero);
    const int foot = nao.body->linkIndex("LFoot");
    const engine::Pose torso = robot.physics.linkPose(robot.id, 0);
    const engine::Pose foot_pose = robot.physics.linkPose(robot.id, foot);
    const Vec3 ankle = torso.inverse() * foot_pose.translation();
    EXPECT_NEAR(ankle.x(), 0.0, 1e-4);
    EXPECT_NEAR(ankle.y(), 0.050, 1e-4);
    EXPECT_NEAR(ankle.z(), -0.2879, 1e-4);  // nao.md 2.2: LAnkle (0, 50, -287.9)
    const auto& box = nao.body->links[static_cast<size_t>(foot)].shapes.at(0);
    const double sole = ankle.z() + box.pose.translation().z() - 0.5 * box.extents.z();
    EXPECT_NEAR(sole, -0.33309, 0.001);
  }
}

namespace {

// Every joint of a robot file, read independently of the loader, against the
// model it built and against Bullet's placement of the links.
void checkJointsAgainstTheFile(const std::filesystem::path& file) {
  SCOPED_TRACE(file.string());
  const auto nao = robots::loadRobotModel(file);
  const YAML::Node doc = YAML::LoadFile(file.string());
  ASSERT_EQ(doc["joints"].size(), nao.body->joints.size());
  const std::vector<double> zero(nao.body->joints.size(), 0.0);
  for (const YAML::Node& j : doc["joints"]) {
    const std::string name = j["name"].as<std::string>();
    const int idx = nao.body->jointIndex(name);
    ASSERT_GE(idx, 0) << name;
    const auto& joint = nao.body->joints[static_cast<size_t>(idx)];
    const auto axis = j["axis"].as<std::vector<double>>();
    const auto limits = j["limits"].as<std::vector<double>>();
    EXPECT_NEAR(joint.lower, limits[0], 1e-12) << name;
    EXPECT_NEAR(joint.upper, limits[1], 1e-12) << name;
    const Vec3 data_axis = Vec3(axis[0], axis[1], axis[2]).normalized();
    EXPECT_LT((joint.axis - data_axis).norm(), 1e-9) << name;

    // Bullet rotates the child link about that axis: turn the joint by 0.3 rad.
    std::vector<double> q = zero;
    q[static_cast<size_t>(idx)] = 0.3;
    FloatingRobot robot(nao, q);
    const engine::Pose parent = robot.physics.linkPose(robot.id, joint.parent_link);
    const engine::Pose child = robot.physics.linkPose(robot.id, joint.child_link);
    const Eigen::AngleAxisd rel(parent.linear().transpose() * child.linear());
    EXPECT_NEAR(rel.angle(), 0.3, 1e-4) << name;
    EXPECT_LT((rel.axis() - data_axis).norm(), 1e-3) << name;
    const Vec3 origin = parent.inverse() * child.translation();
    EXPECT_LT((origin - joint.origin).norm(), 1e-5) << name;
  }
}

}  // namespace

TEST(RobotModel, JointLimitsAndAxesAsInTheData) {
  checkJointsAgainstTheFile(test::naoH25());
  const auto nao = robots::loadRobotModel(test::naoH25());
  // Spot checks against the reference table (nao.md 2.2).
  const auto& hyp = nao.body->joints[static_cast<size_t>(nao.body->jointIndex("LHipYawPitch"))];
  EXPECT_LT((hyp.axis - Vec3(0, std::sqrt(0.5), -std::sqrt(0.5))).norm(), 1e-6);
  EXPECT_NEAR(hyp.lower, -1.14529, 1e-9);
  EXPECT_NEAR(hyp.upper, 0.740718, 1e-9);
  const auto& knee = nao.body->joints[static_cast<size_t>(nao.body->jointIndex("RKneePitch"))];
  EXPECT_NEAR(knee.lower, -0.0923279, 1e-9);
  EXPECT_NEAR(knee.upper, 2.11255, 1e-9);
  EXPECT_NEAR(knee.origin.z(), -0.100, 1e-12);
}

TEST(RobotModel, ActuatorsFollowLolaOrder) {
  const auto nao = robots::loadRobotModel(test::naoH25());
  const char* lola[25] = {
      "HeadYaw",    "HeadPitch",   "LShoulderPitch", "LShoulderRoll",  "LElbowYaw",
      "LElbowRoll", "LWristYaw",   "LHipYawPitch",   "LHipRoll",       "LHipPitch",
      "LKneePitch", "LAnklePitch", "LAnkleRoll",     "RHipRoll",       "RHipPitch",
      "RKneePitch", "RAnklePitch", "RAnkleRoll",     "RShoulderPitch", "RShoulderRoll",
      "RElbowYaw",  "RElbowRoll",  "RWristYaw",      "LHand",          "RHand"};
  for (int i = 0; i < 25; ++i) EXPECT_EQ(nao.actuators[static_cast<size_t>(i)].name, lola[i]);
  // The right HipYawPitch is no actuator: it mimics the left one.
  const auto& r = nao.body->joints[static_cast<size_t>(nao.body->jointIndex("RHipYawPitch"))];
  EXPECT_EQ(r.mimic_of, nao.body->jointIndex("LHipYawPitch"));
}

TEST(RobotModel, SensorFramesFromReference) {
  const auto nao = robots::loadRobotModel(test::naoH25());
  const auto* cam = nao.sensor("CameraTop");
  ASSERT_NE(cam, nullptr);
  EXPECT_EQ(nao.body->links[static_cast<size_t>(cam->link)].name, "Head");
  EXPECT_NEAR(cam->pose.translation().x(), 0.05871, 1e-9);
  EXPECT_NEAR(cam->pose.translation().z(), 0.06364, 1e-9);
  int fsr = 0;
  for (const auto& s : nao.sensors) fsr += s.type == "fsr";
  EXPECT_EQ(fsr, 8);
}

TEST(RobotModel, StandPoseHasFlatFeetUnderTheHips) {
  const auto nao = robots::loadRobotModel(test::naoH25());
  const auto frames = nao.body->linkFramesAt(nao.pose("stand"));
  for (const char* side : {"L", "R"}) {
    const auto& foot = frames[static_cast<size_t>(nao.body->linkIndex(std::string(side) + "Foot"))];
    const auto& hip = frames[static_cast<size_t>(nao.body->linkIndex(std::string(side) + "Hip"))];
    EXPECT_NEAR(foot.linear()(2, 2), 1.0, 1e-9) << side;  // sole parallel to the torso's xy plane
    EXPECT_NEAR(foot.translation().x(), hip.translation().x(), 0.005) << side;  // ankle under hip
  }
}

// Independent numbers typed from docs/reference.md, Nao V6 section 2.2 (not
// read from our YAML): right-side signs and the mirrored hip axes.
TEST(RobotModel, RightSideMatchesReferenceTable) {
  const auto nao = robots::loadRobotModel(test::naoH25());
  struct Row {
    const char* name;
    double lower, upper;
    Vec3 origin, axis;
  };
  const double s = std::sqrt(0.5);
  const Row rows[] = {
      {"RShoulderPitch", -2.08567, 2.08567, {0, -0.098, 0.100}, {0, 1, 0}},
      {"RShoulderRoll", -1.32645, 0.314159, {0, 0, 0}, {0, 0, 1}},
      {"RElbowYaw", -2.08567, 2.08567, {0.105, -0.015, 0}, {1, 0, 0}},
      {"RElbowRoll", 0.0349066, 1.54462, {0, 0, 0}, {0, 0, 1}},
      {"RWristYaw", -1.82387, 1.82387, {0.05595, 0, 0}, {1, 0, 0}},
      {"RHipYawPitch", -1.14529, 0.740718, {0, -0.050, -0.085}, {0, s, s}},
      {"RHipRoll", -0.79046, 0.379435, {0, 0, 0}, {1, 0, 0}},
      {"RHipPitch", -1.53589, 0.48398, {0, 0, 0}, {0, 1, 0}},
      {"RKneePitch", -0.0923279, 2.11255, {0, 0, -0.100}, {0, 1, 0}},
      {"RAnklePitch", -1.1863, 0.932006, {0, 0, -0.1029}, {0, 1, 0}},
      {"RAnkleRoll", -0.768992, 0.397761, {0, 0, 0}, {1, 0, 0}},
      {"LHipRoll", -0.379435, 0.79046, {0, 0, 0}, {1, 0, 0}},
      {"LAnkleRoll", -0.397761, 0.768992, {0, 0, 0}, {1, 0, 0}},
      {"HeadPitch", -0.671952, 0.514872, {0, 0, 0}, {0, 1, 0}},
  };
  for (const Row& r : rows) {
    const int j = nao.body->jointIndex(r.name);
    ASSERT_GE(j, 0) << r.name;
    const auto& joint = nao.body->joints[static_cast<size_t>(j)];
    EXPECT_NEAR(joint.lower, r.lower, 1e-6) << r.name;
    EXPECT_NEAR(joint.upper, r.upper, 1e-6) << r.name;
    EXPECT_LT((joint.origin - r.origin).norm(), 1e-9) << r.name;
    EXPECT_LT((joint.axis - r.axis.normalized()).norm(), 1e-6) << r.name;
  }
  // Masses (nao.md 4.1): right thigh and foot, head.
  EXPECT_NEAR(nao.body->links[static_cast<size_t>(nao.body->linkIndex("RThigh"))].mass, 0.38968,
              1e-9);
  EXPECT_NEAR(nao.body->links[static_cast<size_t>(nao.body->linkIndex("RFoot"))].com.y(), -0.0033,
              1e-9);
  EXPECT_NEAR(nao.body->links[static_cast<size_t>(nao.body->linkIndex("Head"))].mass, 0.65973,
              1e-9);
}

// A link's own material is the one its collider meets the ground with: two
// boxes of the same body material (friction 0.2) under gravity tilted 0.4
// sideways, one with a root link material of 0.8 of its own; on a ground of
// 1.0 the first slides, the second holds.
TEST(RobotModel, ALinksOwnMaterialReachesTheContacts) {
  engine::PhysicsSettings settings;
  settings.gravity = Vec3(0.4 * 9.81, 0.0, -9.81);
  engine::PhysicsWorld physics(settings);
  physics.addGround({1.0, 0.0, 0.0, 0.0});
  auto box = [](std::optional<engine::Material> own) {
    auto m = std::make_shared<engine::ArticulatedModel>();
    m->name = "box";
    m->material = {0.2, 0.0, 0.0, 0.0};
    engine::Link l;
    l.name = "root";
    l.mass = 1.0;
    l.inertia = Vec3(0.0042, 0.0042, 0.0067).asDiagonal();  // 0.2 x 0.2 x 0.1 m
    engine::Shape s;
    s.type = engine::ShapeType::Box;
    s.extents = Vec3(0.2, 0.2, 0.1);
    l.shapes.push_back(s);
    l.material = own;
    m->links.push_back(l);
    return std::shared_ptr<const engine::ArticulatedModel>(m);
  };
  engine::Pose at = engine::Pose::Identity();
  at.translation() = Vec3(0, -1, 0.05);
  const auto slides = physics.addArticulation(box(std::nullopt), at, {}, 0);
  at.translation() = Vec3(0, 1, 0.05);
  const auto holds = physics.addArticulation(box(engine::Material{0.8, 0.0, 0.0, 0.0}), at, {}, 1);
  for (int i = 0; i < 200; ++i) physics.step();  // 1 s
  const double slid = physics.linkPose(slides, 0).translation().x();
  const double held = physics.linkPose(holds, 0).translation().x();
  std::printf("body material 0.2: slid %.3f m; own material 0.8: %.4f m\n", slid, held);
  EXPECT_GT(slid, 0.5);  // (0.4 - 0.2) g / 2 over 1 s: about 1 m
  EXPECT_LT(std::abs(held), 0.01);
}

// The Booster K1 (robots/booster_k1.yaml) against the numbers of its sources,
// typed here from docs/models.md's K1 table (booster_assets@486da0f, the
// Booster SDK's JointIndexK1), not read from the YAML.
TEST(BoosterK1, MassJointsAndTheSdksJointOrder) {
  const auto k1 = robots::loadRobotModel(test::boosterK1());
  EXPECT_NEAR(k1.body->totalMass(), 19.67, 0.01 * 19.67);  // booster_assets: 19.67 kg
  EXPECT_EQ(k1.body->links.size(), 23u);                   // trunk + 22 hinge links
  EXPECT_EQ(k1.body->joints.size(), 22u);
  EXPECT_TRUE(k1.hands.empty());
  // JointIndexK1: the order of LowState's and LowCmd's 22 motor entries.
  const char* sdk[22] = {
      "HeadYaw",         "HeadPitch",     "LeftShoulderPitch",  "LeftShoulderRoll",
      "LeftElbowPitch",  "LeftElbowYaw",  "RightShoulderPitch", "RightShoulderRoll",
      "RightElbowPitch", "RightElbowYaw", "LeftHipPitch",       "LeftHipRoll",
      "LeftHipYaw",      "LeftKneePitch", "LeftAnklePitch",     "LeftAnkleRoll",
      "RightHipPitch",   "RightHipRoll",  "RightHipYaw",        "RightKneePitch",
      "RightAnklePitch", "RightAnkleRoll"};
  ASSERT_EQ(k1.actuators.size(), 22u);
  for (size_t a = 0; a < 22; ++a) {
    EXPECT_EQ(k1.actuators[a].name, sdk[a]) << "entry " << a;
    EXPECT_EQ(k1.actuators[a].kind, robots::Actuator::Kind::Joint) << sdk[a];
  }
  // An IMU in the trunk, one head camera; no foot pressure sensors, sonars or touch.
  for (const auto& sensor : k1.sensors)
    EXPECT_TRUE(sensor.type == "accelerometer" || sensor.type == "gyroscope" ||
                sensor.type == "camera")
        << sensor.name << " " << sensor.type;
  ASSERT_EQ(k1.cameraCount(), 1u);
  EXPECT_EQ(k1.body->links[static_cast<size_t>(k1.camera(0).link)].name, "Head");
  EXPECT_EQ(k1.sensor("Accelerometer")->link, 0);
}

TEST(BoosterK1, LimitsAxesAndOffsetsOfTheSources) {
  checkJointsAgainstTheFile(test::boosterK1());
  const auto k1 = robots::loadRobotModel(test::boosterK1());
  struct Row {
    const char* name;
    double lower, upper;
    Vec3 origin, axis;
    double effort, speed;
  };
  const Row rows[] = {
      {"HeadYaw", -1.0, 1.0, {0.0056, 0, 0.2149}, {0, 0, 1}, 6, 18},
      {"HeadPitch", -0.349, 0.855, {0, 0, 0.033}, {0, 1, 0}, 6, 18},
      {"LeftShoulderPitch", -3.316, 1.22, {0, 0.077, 0.1845}, {0, 1, 0}, 14, 18},
      {"LeftShoulderRoll", -1.74, 1.57, {0.0025, 0.068, -0.0135}, {1, 0, 0}, 14, 18},
      {"LeftElbowYaw", -2.44, 0.0, {0, 0.1215, 0}, {0, 0, 1}, 14, 18},
      {"RightShoulderRoll", -1.57, 1.74, {0.0025, -0.068, -0.0135}, {1, 0, 0}, 14, 18},
      {"RightElbowYaw", 0.0, 2.44, {0, -0.1215, 0}, {0, 0, 1}, 14, 18},
      {"LeftHipPitch", -3.0, 2.21, {0, 0.096, -0.077}, {0, 1, 0}, 30, 7.1},
      {"LeftHipRoll", -0.4, 1.57, {0, 0, -0.026}, {1, 0, 0}, 35, 12.9},
      {"LeftHipYaw", -1.0, 1.0, {0.012, 0, -0.0485}, {0, 0, 1}, 20, 18.1},
      {"LeftKneePitch", 0.0, 2.23, {-0.014, 0, -0.117}, {0, 1, 0}, 40, 12.5},
      {"LeftAnklePitch", -0.87, 0.345, {0.0002, 0.0002, -0.24519}, {0, 1, 0}, 20, 18.1},
      {"LeftAnkleRoll", -0.345, 0.345, {0, 0, 0}, {1, 0, 0}, 20, 18.1},
      {"RightHipRoll", -1.57, 0.4, {0, 0, -0.026}, {1, 0, 0}, 35, 12.9},
  };
  for (const Row& r : rows) {
    const int j = k1.body->jointIndex(r.name);
    ASSERT_GE(j, 0) << r.name;
    const auto& joint = k1.body->joints[static_cast<size_t>(j)];
    EXPECT_NEAR(joint.lower, r.lower, 1e-6) << r.name;
    EXPECT_NEAR(joint.upper, r.upper, 1e-6) << r.name;
    EXPECT_LT((joint.origin - r.origin).norm(), 1e-4) << r.name;
    EXPECT_LT((joint.axis - r.axis).norm(), 1e-9) << r.name;
    const auto& motor = k1.body->motors[static_cast<size_t>(joint.motor)];
    EXPECT_DOUBLE_EQ(motor.stall_torque, r.effort) << r.name;
    EXPECT_DOUBLE_EQ(motor.no_load_speed, r.speed) << r.name;
  }
  // Masses of the table: trunk, head, shank, foot.
  auto mass = [&](const char* link) {
    return k1.body->links[static_cast<size_t>(k1.body->linkIndex(link))].mass;
  };
  EXPECT_DOUBLE_EQ(mass("Trunk"), 6.5);
  EXPECT_DOUBLE_EQ(mass("Head"), 0.7);
  EXPECT_DOUBLE_EQ(mass("LeftShank"), 1.5);
  EXPECT_DOUBLE_EQ(mass("RightFoot"), 0.494);
}

// booster_assets at zero pose: the trunk origin 0.552 m above the soles,
// the top of the head 0.954 m (docs/models.md), through the loader and Bullet.
TEST(BoosterK1, ZeroPoseHeights) {
  const auto k1 = robots::loadRobotModel(test::boosterK1());
  const std::vector<double> zero(k1.body->joints.size(), 0.0);
  const double sole = k1.soleDepth(zero);
  EXPECT_NEAR(sole, 0.552, 0.003);
  FloatingRobot robot(k1, zero);
  double top = -1.0;
  for (size_t l = 0; l < k1.body->links.size(); ++l) {
    const engine::Pose pose = robot.physics.linkPose(robot.id, static_cast<int>(l));
    for (const auto& shape : k1.body->links[l].shapes)
      if (shape.type == engine::ShapeType::Sphere)
        top = std::max(top, (pose * shape.pose).translation().z() + shape.radius);
  }
  const double trunk = robot.physics.linkPose(robot.id, 0).translation().z();
  EXPECT_NEAR(top - trunk + sole, 0.954, 0.01);
  // The ankles: straight under the hips, 0.077 + 0.026 + 0.0485 + 0.117 + 0.24519 below the trunk.
  const Vec3 ankle = robot.physics.linkPose(robot.id, 0).inverse() *
                     robot.physics.linkPose(robot.id, k1.body->linkIndex("LeftFoot")).translation();
  EXPECT_NEAR(ankle.z(), -(0.077 + 0.026 + 0.0485 + 0.117 + 0.24519), 1e-4);
  EXPECT_NEAR(ankle.y(), 0.096 + 0.0002, 1e-4);
}

TEST(BoosterK1, StandPoseHasFlatFeetUnderTheHips) {
  const auto k1 = robots::loadRobotModel(test::boosterK1());
  const auto frames = k1.body->linkFramesAt(k1.pose("stand"));
  for (const char* side : {"Left", "Right"}) {
    const auto& foot = frames[static_cast<size_t>(k1.body->linkIndex(std::string(side) + "Foot"))];
    const auto& hip = frames[static_cast<size_t>(k1.body->linkIndex(std::string(side) + "Hip"))];
    EXPECT_NEAR(foot.linear()(2, 2), 1.0, 1e-9) << side;
    EXPECT_NEAR(foot.translation().x(), hip.translation().x(), 0.03) << side;
  }
}
