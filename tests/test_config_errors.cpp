// Every config error stops at load with a message naming the file, the key
// path and the reason.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>

#include "simsoccer/engine/config.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/robots/robot_model.hpp"
#include "simsoccer/world/world.hpp"
#include "test_support.hpp"

using namespace simsoccer;
namespace fs = std::filesystem;

// At namespace scope, not in the anonymous one: GoogleTest derives each test's class from
// it, and in a unity build GCC warns of a base that has internal linkage.
class ConfigErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = std::make_unique<test::TempDir>(
        "cfg_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    dir_ = tmp_->path();
    robot_ = test::readFile(test::naoH25());
    scenario_ = test::readFile(test::sourceDir() / "configs" / "scenarios" / "lineup_5v5.yaml");
    // Point the copied scenario at the copied robot file and the real field.
    replace(scenario_, "../../fields/spl.yaml", test::splField().string());
    replace(scenario_, "../../robots/nao_v6_h25.yaml", (dir_ / "robot.yaml").string());
    replace(scenario_, "../../robots/nao_h21.yaml", test::naoH21().string());
  }
  void TearDown() override { tmp_.reset(); }

  static void replace(std::string& s, const std::string& from, const std::string& to) {
    const size_t at = s.find(from);
    ASSERT_NE(at, std::string::npos) << "test set-up: '" << from << "' not found";
    s.replace(at, from.size(), to);
  }

  // Writes both files and loads the world; returns the error.
  engine::ConfigError load() {
    std::ofstream(dir_ / "robot.yaml") << robot_;
    std::ofstream(dir_ / "scenario.yaml") << scenario_;
    try {
      world::World w = world::World::fromFile(dir_ / "scenario.yaml");
    } catch (const engine::ConfigError& e) {
      return e;
    }
    ADD_FAILURE() << "no ConfigError";
    return engine::ConfigError("", "", "");
  }

  void expectError(const std::string& file, const std::string& key, const std::string& reason) {
    const engine::ConfigError e = load();
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos) << what;
    EXPECT_EQ(e.key(), key) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what;
  }

  std::unique_ptr<test::TempDir> tmp_;  // removed after each test
  fs::path dir_;
  std::string robot_, scenario_;
};

namespace {}  // namespace

TEST_F(ConfigErrors, ValidFilesLoad) {
  std::ofstream(dir_ / "robot.yaml") << robot_;
  std::ofstream(dir_ / "scenario.yaml") << scenario_;
  world::World w = world::World::fromFile(dir_ / "scenario.yaml");
  EXPECT_EQ(w.robotCount(), 10u);
  EXPECT_EQ(w.robot(9).model->name, "nao_h21");
}

TEST_F(ConfigErrors, MissingKey) {
  replace(scenario_, "  dt: 0.010               # s, physics step\n", "");
  expectError("scenario.yaml", "physics.dt", "missing required key");
}

TEST_F(ConfigErrors, ContactWarmStartIsAShare) {
  replace(scenario_, "contact_warm_start: 1.0", "contact_warm_start: 1.5");
  expectError("scenario.yaml", "physics.contact_warm_start", "must be 0..1");
}

TEST_F(ConfigErrors, JointSweepsMustBeACountFrom1To16) {
  replace(scenario_, "joint_sweeps: 2", "joint_sweeps: 0");
  expectError("scenario.yaml", "physics.joint_sweeps", "must be 1..16");
}

TEST_F(ConfigErrors, WrongType) {
  replace(scenario_, "solver_iterations: 10", "solver_iterations: many");
  expectError("scenario.yaml", "physics.solver_iterations", "expected an integer");
}

TEST_F(ConfigErrors, SolverThreadsMustBeAutoOrACount) {
  replace(scenario_, "threads: auto", "threads: two");
  expectError("scenario.yaml", "physics.threads",
              "must be auto or a whole number from 1 to 64, got 'two'");
}

TEST_F(ConfigErrors, UnknownKeyIsATypo) {
  replace(scenario_, "seed: 7", "seed: 7\nsede: 8");
  expectError("scenario.yaml", "sede", "unknown key");
}

TEST_F(ConfigErrors, NegativeSelfPoseCorrelationTime) {
  replace(scenario_, "seed: 7", "seed: 7\nperception: {profile: realistic, pose_noise_time: -1}");
  expectError("scenario.yaml", "perception.pose_noise_time", "must be >= 0, got -1");
}

TEST_F(ConfigErrors, UnknownJointName) {
  replace(robot_, "stand: {LHipPitch: -0.45", "stand: {LHipPich: -0.45");
  expectError("robot.yaml", "poses.stand.LHipPich", "unknown joint 'LHipPich'");
}

TEST_F(ConfigErrors, UnknownMimicJoint) {
  replace(robot_, "mimic: {joint: LHipYawPitch", "mimic: {joint: LHipYawPich");
  expectError("robot.yaml", "joints[18].mimic.joint", "unknown joint 'LHipYawPich'");
}

TEST_F(ConfigErrors, UnknownLinkName) {
  replace(robot_, "parent: LThigh, child: LTibia", "parent: LThig, child: LTibia");
  expectError("robot.yaml", "joints[15].parent", "unknown link 'LThig'");
}

TEST_F(ConfigErrors, UnknownFootLink) {
  replace(robot_, "legs: {left: LFoot, right: RFoot}", "legs: {left: LFot, right: RFoot}");
  expectError("robot.yaml", "legs.left", "unknown foot link 'LFot'");
}

TEST_F(ConfigErrors, FallenTorsoHeightMissing) {
  replace(robot_, "fallen_torso_height: 0.22", "");
  expectError("robot.yaml", "fallen_torso_height", "missing required key");
}

TEST_F(ConfigErrors, FallenTorsoHeightAboveTheStandingTorso) {
  // A robot in its stand pose would count as fallen.
  replace(robot_, "fallen_torso_height: 0.22", "fallen_torso_height: 0.4");
  expectError("robot.yaml", "fallen_torso_height",
              "must be below the torso's height in the stand pose");
}

TEST_F(ConfigErrors, BothLegsOnOneFoot) {
  replace(robot_, "legs: {left: LFoot, right: RFoot}", "legs: {left: LFoot, right: LFoot}");
  expectError("robot.yaml", "legs.right", "the right foot is the left foot's link");
}

TEST_F(ConfigErrors, NonPositiveMass) {
  replace(robot_, "mass: 0.65973", "mass: 0");
  expectError("robot.yaml", "links[2].mass", "must be > 0");
}

TEST_F(ConfigErrors, BadSoleMaterial) {
  replace(robot_,
          "    material: {friction: 0.625}   # rubber sole\n    collision:\n      - {box: {size: "
          "[0.160, 0.090, 0.035]}, position: [0.0225, 0.0075",
          "    material: {friction: -1.0}   # rubber sole\n    collision:\n      - {box: {size: "
          "[0.160, 0.090, 0.035]}, position: [0.0225, 0.0075");
  expectError("robot.yaml", "links[13].material.friction", "must be >= 0");
}

// One collider per moving link, so one material: a link fixed to another
// (the H21's rigid hand) cannot keep its own.
TEST_F(ConfigErrors, AFixedLinkWithItsOwnMaterial) {
  robot_ = test::readFile(test::naoH21());
  replace(robot_, "  - name: LHand   # rigid hand, fixed to the forearm\n",
          "  - name: LHand   # rigid hand, fixed to the forearm\n    material: {friction: 1.0}\n");
  expectError("robot.yaml", "joints[6].child", "'LHand' has a material of its own");
}

TEST_F(ConfigErrors, RobotOutsideTheField) {
  replace(scenario_, "pose: [-3.0, 1.0, 0.0]", "pose: [-3.0, 9.0, 0.0]");
  expectError("scenario.yaml", "robots[1].pose", "outside the field");
}

TEST_F(ConfigErrors, DuplicatePlayerNumber) {
  replace(scenario_, "{team: 0, number: 3,", "{team: 0, number: 2,");
  expectError("scenario.yaml", "robots[2].number", "duplicate player number 2 in team 0");
}

TEST_F(ConfigErrors, ControlPeriodNotAMultipleOfDt) {
  replace(scenario_, "control_period: 0.010", "control_period: 0.012");
  expectError("scenario.yaml", "physics.control_period", "whole multiple of dt");
}

TEST_F(ConfigErrors, UnknownPosture) {
  replace(scenario_, "posture: stand", "posture: crouch");
  expectError("scenario.yaml", "robots[4].posture", "has no pose 'crouch'");
}

TEST_F(ConfigErrors, PoseOutsideJointLimits) {
  replace(robot_, "LKneePitch: 0.9", "LKneePitch: 2.5");
  expectError("robot.yaml", "poses.stand.LKneePitch", "outside the joint limits");
}

TEST_F(ConfigErrors, MissingFile) {
  replace(scenario_, test::splField().string(), "no_such_field.yaml");
  expectError("scenario.yaml", "field", "file not found");
}

TEST_F(ConfigErrors, SyntaxError) {
  scenario_ += "\nrobots: [unclosed\n";
  expectError("scenario.yaml", "", "YAML syntax error at line");
}

TEST_F(ConfigErrors, BadFieldValue) {
  std::string field = test::readFile(test::splField());
  replace(field, "width: 6.0", "width: -6.0");
  std::ofstream(dir_ / "field.yaml") << field;
  try {
    fields::loadFieldModel(dir_ / "field.yaml");
    ADD_FAILURE() << "no ConfigError";
  } catch (const engine::ConfigError& e) {
    EXPECT_EQ(e.key(), "width");
    EXPECT_NE(std::string(e.what()).find("field.yaml"), std::string::npos);
  }
}

TEST_F(ConfigErrors, MimicJointWithItsOwnMotor) {
  replace(robot_, "mimic: {joint: LHipYawPitch, multiplier: 1.0}}",
          "mimic: {joint: LHipYawPitch, multiplier: 1.0}, motor: leg_yaw_roll}");
  expectError("robot.yaml", "joints[18].motor", "driven by its master's motor");
}

TEST_F(ConfigErrors, LinkAttachedTwice) {
  replace(robot_, "parent: LThigh, child: LTibia", "parent: LThigh, child: LHip");
  expectError("robot.yaml", "joints[15].child", "already attached by joint 'LHipRoll'");
}

TEST_F(ConfigErrors, OverlappingRobots) {
  replace(scenario_, "pose: [-3.0, -1.0, 0.0]", "pose: [-3.0, 0.95, 0.0]");
  expectError("scenario.yaml", "robots[2].pose", "overlaps robots[1]");
}

TEST_F(ConfigErrors, BallBelowTheCarpet) {
  replace(scenario_, "ball: {position: [0.0, 0.0]}", "ball: {position: [0.0, 0.0, 0.01]}");
  expectError("scenario.yaml", "ball.position", "at least its radius");
}

TEST_F(ConfigErrors, DirectoryInsteadOfFile) {
  replace(scenario_, test::splField().string(), test::sourceDir().string());
  const engine::ConfigError e = load();
  EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
}

TEST_F(ConfigErrors, UnknownServoIntegration) {
  replace(robot_, "leg_pitch: {servo: implicit,", "leg_pitch: {servo: semi,");
  expectError("robot.yaml", "motors.leg_pitch.servo", "must be implicit or explicit, not 'semi'");
}

TEST_F(ConfigErrors, ExplicitUpToOnlyForAnExplicitServo) {
  replace(robot_, "leg_pitch: {servo: implicit,",
          "leg_pitch: {servo: implicit, explicit_up_to: 0.005,");
  expectError("robot.yaml", "motors.leg_pitch.explicit_up_to", "only for an explicit servo");
}

// Found by probing as a hostile user would: keys that are not strings, keys
// twice (YAML forbids it; yaml-cpp kept the first), a denormal "positive"
// size and absurd sizes all stop the load with file, key and reason.
TEST_F(ConfigErrors, AKeyThatIsNotAString) {
  scenario_ += "[1, 2]: 1\n";
  expectError("scenario.yaml", "", "a key that is not a string");
}

TEST_F(ConfigErrors, AKeyTwice) {
  scenario_ += "seed: 5\nseed: 6\n";
  expectError("scenario.yaml", "seed", "appears twice");
}

TEST_F(ConfigErrors, DenormalAndAbsurdSizes) {
  const auto fieldError = [&](const std::string& from, const std::string& to) {
    std::string field = test::readFile(test::splField());
    replace(field, from, to);
    std::ofstream(dir_ / "field.yaml") << field;
    try {
      fields::loadFieldModel(dir_ / "field.yaml");
    } catch (const engine::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("field.yaml"), std::string::npos) << e.what();
      return std::string(e.what());
    }
    ADD_FAILURE() << to << " was accepted";
    return std::string();
  };
  EXPECT_NE(fieldError("radius: 0.05", "radius: 1e-320").find("normal positive"),
            std::string::npos);
  EXPECT_NE(fieldError("border: 0.7", "border: 1.2e11").find("border"), std::string::npos);
  EXPECT_NE(fieldError("width: 6.0", "width: 600.0").find("no soccer field"), std::string::npos);
}

// Aliases that make a loop or an exponential tree stop the load with an error
// (they crashed or hung the key check before it was bounded; fuzz seeds keep them).
TEST_F(ConfigErrors, AliasLoopsAndBlowUps) {
  scenario_ += "loop: &x [*x]\n";
  const engine::ConfigError e = load();
  EXPECT_NE(std::string(e.what()).find("alias loop"), std::string::npos) << e.what();
  EXPECT_EQ(e.key().rfind("loop", 0), 0u) << e.what();
  std::string bomb = "a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n";
  for (char c = 'b'; c <= 'h'; ++c) {
    bomb += std::string(1, c) + ": &" + c + " [";
    for (int i = 0; i < 10; ++i) bomb += std::string(i ? ", *" : "*") + static_cast<char>(c - 1);
    bomb += "]\n";
  }
  std::ofstream(dir_ / "bomb.yaml") << "scenario: x\n" << bomb;
  try {
    world::loadScenario(dir_ / "bomb.yaml");
    ADD_FAILURE() << "an alias bomb was accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("alias loop"), std::string::npos) << e.what();
  }
}
