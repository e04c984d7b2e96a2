// Robots holding the stand pose on the carpet, and collapsing limp (real Bullet).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "simsoccer/world/world.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

double tiltOf(const engine::Pose& torso) {
  return std::acos(std::clamp(torso.linear()(2, 2), -1.0, 1.0));
}

}  // namespace

struct StandCase {
  const char* file;
  double settle;    // s to settle onto the feet before measuring
  double max_tilt;  // rad from the vertical, standing still
};

class StandModels : public ::testing::TestWithParam<StandCase> {};

TEST_P(StandModels, StiffStandPoseStaysUprightFor30Seconds) {
  world::Scenario s = test::scenario(1);
  s.robot_model_file = test::sourceDir() / "robots" / GetParam().file;
  world::World w(s);
  const int settle = static_cast<int>(std::lround(GetParam().settle / w.scenario().physics.dt));
  for (int i = 0; i < settle; ++i) w.step();
  const engine::Pose start = w.torsoPose(0);
  const double start_tilt = tiltOf(start);
  double max_dz = 0.0, max_tilt = 0.0, max_drift = 0.0;
  const int steps = static_cast<int>(std::lround(30.0 / w.scenario().physics.dt));
  for (int i = 0; i < steps; ++i) {
    w.step();
    if (i % 20 == 0) {
      const engine::Pose p = w.torsoPose(0);
      max_dz = std::max(max_dz, std::abs(p.translation().z() - start.translation().z()));
      max_tilt = std::max(max_tilt, tiltOf(p));
      max_drift = std::max(max_drift, std::abs(tiltOf(p) - start_tilt));
    }
  }
  const engine::Pose end = w.torsoPose(0);
  std::printf(
      "%s: torso height start %.4f end %.4f, max |dz| %.4f m, tilt settled %.2f max %.2f deg "
      "(about the world y axis %.2f deg)\n",
      GetParam().file, start.translation().z(), end.translation().z(), max_dz,
      start_tilt * 180 / M_PI, max_tilt * 180 / M_PI,
      std::asin(std::clamp(end.linear()(0, 2), -1.0, 1.0)) * 180 / M_PI);
  EXPECT_LT(max_dz, 0.01);
  EXPECT_LT(max_tilt, GetParam().max_tilt);
  EXPECT_LT(max_drift, 1.0 * M_PI / 180.0);  // settled: no creeping, no sway
  EXPECT_TRUE(w.isStanding(0));
}

// At the default 10 ms step the contacts' warm start holds the Nao: with
// `contact_warm_start: 0` the H25 rocked up to 4.1 deg here (0.5 deg warm).
INSTANTIATE_TEST_SUITE_P(Robots, StandModels,
                         ::testing::Values(StandCase{"nao_v6_h25.yaml", 1.0, 3.0 * M_PI / 180.0},
                                           StandCase{"nao_h21.yaml", 1.0, 3.0 * M_PI / 180.0},
                                           // The K1 (20 kg) on its stiff leg servos: a 0.6
                                           // deg lean (with Booster's deploy gains, 80 / 2,
                                           // it sagged into 4.4 deg).
                                           StandCase{"booster_k1.yaml", 3.0, 3.0 * M_PI / 180.0}));

class LimpModels : public ::testing::TestWithParam<const char*> {};

TEST_P(LimpModels, ZeroStiffnessCollapses) {
  world::Scenario s = test::scenario(1);
  s.robot_model_file = test::sourceDir() / "robots" / GetParam();
  world::World w(s);
  const double start = w.torsoPose(0).translation().z();
  const auto& joints = w.robot(0).model->body->joints;
  for (int j = 0; j < static_cast<int>(joints.size()); ++j)
    if (joints[static_cast<size_t>(j)].mimic_of < 0) w.setJointTarget(0, j, 0.0, 0.0);
  for (int i = 0; i < 600; ++i) w.step();  // 3 s
  const double end = w.torsoPose(0).translation().z();
  std::printf("%s limp: torso height %.3f -> %.3f m\n", GetParam(), start, end);
  EXPECT_LT(end, start - 0.1);
  EXPECT_FALSE(w.isStanding(0));
}

INSTANTIATE_TEST_SUITE_P(Robots, LimpModels,
                         ::testing::Values("nao_v6_h25.yaml", "booster_k1.yaml"));
