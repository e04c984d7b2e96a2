// A Nao holding the stand pose on the carpet (real Bullet).
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

class StandModels : public ::testing::TestWithParam<const char*> {};

TEST_P(StandModels, StiffStandPoseStaysUprightFor30Seconds) {
  world::Scenario s = test::scenario(1);
  s.robot_model_file = test::sourceDir() / "robots" / GetParam();
  world::World w(s);
  for (int i = 0; i < 200; ++i) w.step();  // 1 s to settle onto the feet
  const engine::Pose start = w.torsoPose(0);
  double max_dz = 0.0, max_tilt = 0.0;
  const int steps = static_cast<int>(std::lround(30.0 / w.scenario().physics.dt));
  for (int i = 0; i < steps; ++i) {
    w.step();
    if (i % 20 == 0) {
      const engine::Pose p = w.torsoPose(0);
      max_dz = std::max(max_dz, std::abs(p.translation().z() - start.translation().z()));
      max_tilt = std::max(max_tilt, tiltOf(p));
    }
  }
  const engine::Pose end = w.torsoPose(0);
  std::printf("%s: torso height start %.4f end %.4f, max |dz| %.4f m, max tilt %.2f deg\n",
              GetParam(), start.translation().z(), end.translation().z(), max_dz,
              max_tilt * 180 / M_PI);
  EXPECT_LT(max_dz, 0.01);
  EXPECT_LT(max_tilt, 3.0 * M_PI / 180.0);
  EXPECT_TRUE(w.isStanding(0));
}

INSTANTIATE_TEST_SUITE_P(Nao, StandModels, ::testing::Values("nao_v6_h25.yaml", "nao_h21.yaml"));

TEST(Stand, ZeroStiffnessCollapses) {
  world::World w(test::scenario(1));
  const double start = w.torsoPose(0).translation().z();
  const auto& joints = w.robot(0).model->body->joints;
  for (int j = 0; j < static_cast<int>(joints.size()); ++j)
    if (joints[static_cast<size_t>(j)].mimic_of < 0) w.setJointTarget(0, j, 0.0, 0.0);
  for (int i = 0; i < 600; ++i) w.step();  // 3 s
  const double end = w.torsoPose(0).translation().z();
  std::printf("limp: torso height %.3f -> %.3f m\n", start, end);
  EXPECT_LT(end, start - 0.1);
  EXPECT_FALSE(w.isStanding(0));
}
