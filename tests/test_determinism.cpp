// Same config + seed + commands => same state hash, bit for bit (real Bullet).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>

#include "simsoccer/sim/run_loop.hpp"
#include "simsoccer/world/world.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

// 10 robots, 2,000 steps, every joint driven by a sinusoid (phase per robot).
// `threads`: the solver threads (0: the default); `most_batches`: the most
// constraint batches a step solved side by side; `bullet_solver`: Bullet's
// own rows and iterations (and island loop with one thread).
uint64_t run(uint64_t seed, double amplitude, int steps = 2000, int threads = 0,
             int* most_batches = nullptr, bool bullet_solver = false,
             bool cull_ground_pairs = true) {
  world::Scenario s = test::scenario(10, seed);
  s.physics.threads = threads;
  s.physics.bullet_solver = bullet_solver;
  s.physics.cull_ground_pairs = cull_ground_pairs;
  s.noise.position = 0.01;
  s.noise.yaw = 0.02;
  s.noise.joints = 0.01;
  s.ball_position = {-3.2, -0.6, -1.0};  // next to a robot, so it gets touched
  world::World w(s);
  for (int i = 0; i < steps; ++i) {
    if (i % w.stepsPerControlPeriod() == 0) {
      for (world::RobotId r = 0; r < w.robotCount(); ++r) {
        const auto& model = *w.robot(r).model;
        const auto& stand = model.pose("stand");
        for (size_t j = 0; j < model.body->joints.size(); ++j)
          if (model.body->joints[j].mimic_of < 0)
            w.setJointTarget(r, static_cast<int>(j),
                             stand[j] + amplitude * std::sin(6.0 * w.time() + 0.7 * r + 0.3 * j),
                             1.0);
      }
    }
    w.step();
    if (most_batches) *most_batches = std::max(*most_batches, w.physics().lastStepSolverBatches());
  }
  return w.stateHash();
}

}  // namespace

TEST(Determinism, SameSeedAndCommandsGiveSameHash) {
  const uint64_t a = run(11, 0.1);
  const uint64_t b = run(11, 0.1);
  std::printf("state hash after 2000 steps: %016llx\n", static_cast<unsigned long long>(a));
  EXPECT_EQ(a, b);
}

// The constraint batches are solved side by side on the solver threads; each
// batch alone, as Bullet solves it on one thread: the same state, bit for
// bit, for any number of threads. (Large motions: the robots fall against
// each other, islands merge and split.)
TEST(Determinism, AnyNumberOfSolverThreadsGivesTheSameHash) {
  int batches_one = 0, batches_two = 0, batches_three = 0;
  const uint64_t one = run(21, 0.5, 1500, 1, &batches_one);
  const uint64_t two = run(21, 0.5, 1500, 2, &batches_two);
  const uint64_t three = run(21, 0.5, 1500, 3, &batches_three);
  std::printf("1 thread %016llx, 2 threads %016llx, 3 threads %016llx; up to %d batches a step\n",
              static_cast<unsigned long long>(one), static_cast<unsigned long long>(two),
              static_cast<unsigned long long>(three), batches_two);
  EXPECT_EQ(batches_one, batches_two);  // the same batches, one after the other
  EXPECT_GE(batches_two, 2);            // solved side by side
  EXPECT_GE(batches_three, 2);
  EXPECT_EQ(one, two);
  EXPECT_EQ(one, three);
}

// The engine's batch loop against Bullet's own island loop, both with
// Bullet's rows and iterations (bullet_solver): one thread runs Bullet's
// loop, two the engine's, and the states agree bit for bit.
TEST(Determinism, TheEnginesBatchLoopIsBulletsIslandLoop) {
  int no_batches = 0, batches = 0;
  const uint64_t bullets = run(21, 0.5, 600, 1, &no_batches, /*bullet_solver=*/true);
  const uint64_t engines = run(21, 0.5, 600, 2, &batches, /*bullet_solver=*/true);
  EXPECT_EQ(no_batches, 0);  // Bullet's own loop
  EXPECT_GE(batches, 2);
  EXPECT_EQ(bullets, engines);
}

TEST(Determinism, CullingTheGroundPairsChangesNothing) {
  // Links far above the carpet skip Bullet's narrowphase with it: the same state as Bullet's
  // own narrowphase for every link, while robots swing their limbs hard enough to fall (links
  // coming down to the carpet and leaving it again).
  EXPECT_EQ(run(23, 0.6, 1200, 1, nullptr, false, true),
            run(23, 0.6, 1200, 1, nullptr, false, false));
}

TEST(Determinism, DifferentSeedGivesDifferentHash) {
  EXPECT_NE(run(11, 0.1), run(12, 0.1));
}

TEST(Determinism, DifferentCommandGivesDifferentHash) {
  EXPECT_NE(run(11, 0.1), run(11, 0.11));
}

TEST(Determinism, HashCoversTheState) {
  world::World a(test::scenario(2)), b(test::scenario(2));
  EXPECT_EQ(a.stateHash(), b.stateHash());
  a.step();
  EXPECT_NE(a.stateHash(), b.stateHash());  // time is part of the state
  b.step();
  EXPECT_EQ(a.stateHash(), b.stateHash());
  // At equal step counts: a servo target (a command) is state ...
  const int head_yaw = a.robot(1).model->body->jointIndex("HeadYaw");
  b.setJointTarget(1, head_yaw, 0.1, 1.0);
  EXPECT_NE(a.stateHash(), b.stateHash());
  a.setJointTarget(1, head_yaw, 0.1, 1.0);
  EXPECT_EQ(a.stateHash(), b.stateHash());
  // ... and so is every body: a robot's joint moves, then the ball.
  for (int i = 0; i < 5; ++i) a.step();
  for (int i = 0; i < 4; ++i) b.step();
  b.setJointTarget(1, head_yaw, 0.2, 1.0);
  b.step();
  b.setJointTarget(1, head_yaw, 0.1, 1.0);
  EXPECT_EQ(a.stepCount(), b.stepCount());
  EXPECT_NE(a.stateHash(), b.stateHash());
  world::World c(test::scenario(2)), d(test::scenario(2));
  auto ball = d.ballState();
  ball.linear_velocity.x() += 1e-3;
  d.setBallState(ball);
  EXPECT_NE(c.stateHash(), d.stateHash());
}

TEST(Determinism, SnapshotMatchesWorld) {
  world::World w(test::scenario(3));
  for (int i = 0; i < 50; ++i) w.step();
  const world::WorldSnapshot s = w.snapshot();
  EXPECT_EQ(s.step, 50u);
  EXPECT_DOUBLE_EQ(s.time, 50 * w.scenario().physics.dt);
  ASSERT_EQ(s.robots.size(), 3u);
  EXPECT_TRUE(s.robots[1].torso.isApprox(w.torsoPose(1)));
  EXPECT_EQ(s.robots[2].joint_positions.size(), w.robot(2).model->body->joints.size());
}

TEST(RunLoop, RealTimeNeverRunsAheadOfTheWallClockAndMatchesFreeRunning) {
  // Pacing changes when steps happen, not what they compute.
  world::World paced(test::scenario(2)), free_running(test::scenario(2));
  sim::Simulation simulation(paced);
  const auto t0 = std::chrono::steady_clock::now();
  // 0.4 s simulated at twice real time.
  const sim::RunStats run = sim::RunLoop(simulation, sim::Pacing::RealTime, 2.0).run(40);
  EXPECT_EQ(run.periods, 40);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (int i = 0; i < 40; ++i) free_running.stepControlPeriod();
  EXPECT_GE(wall, 0.2 - 1e-3);  // a lower bound only: never faster than asked
  EXPECT_EQ(paced.stepCount(), free_running.stepCount());
  EXPECT_EQ(paced.stateHash(), free_running.stateHash());
}

namespace {

// Every robot's joints follow a sinusoid about the stand pose, through the
// pipeline's gate (so quantised as a match applies them).
class SinusoidSource : public sim::CommandSource {
 public:
  explicit SinusoidSource(const world::World& w) : world_(w) {}
  void observe(const sim::Observation& o) override { time_ = o.time; }
  void collect(uint64_t, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) override {
    for (world::RobotId r = 0; r < world_.robotCount(); ++r) {
      const auto& model = *world_.robot(r).model;
      const auto& stand = model.pose("stand");
      std::array<double, world::kActuators> position{}, stiffness{};
      for (size_t a = 0; a < model.actuators.size() && a < world::kActuators; ++a) {
        stiffness[a] = 1.0;
        if (model.actuators[a].kind != robots::Actuator::Kind::Joint) continue;
        const auto j = static_cast<size_t>(model.actuators[a].index);
        position[a] =
            stand[j] + 0.15 * std::sin(5.0 * time_ + 0.7 * r + 0.3 * static_cast<double>(a));
      }
      if (auto c =
              gate.check(r, std::span<const double>(position), std::span<const double>(stiffness)))
        slots[r] = {sim::Answer::Given, *c};
    }
  }

 private:
  const world::World& world_;
  double time_ = 0.0;
};

uint64_t goldenScenarioHash(sim::Mode mode, int threads) {
  world::Scenario s = test::scenario(4, 2026);
  s.physics.threads = threads;
  s.ball_position = {-3.2, -0.6, -1.0};  // next to a robot, so it gets touched
  world::World w(s);
  sim::SimulationConfig c;
  c.mode = mode;
  sim::Simulation simulation(w, c);
  SinusoidSource source(w);
  simulation.addSource(source);
  sim::RunLoop(simulation, sim::Pacing::Lockstep).run(200);  // 2 s
  return w.stateHash();
}

}  // namespace

// The pinned state of a short fixed scenario (as Box2D pins EXPECTED_HASH):
// 4 Naos, 2 s of sinusoidal joint commands through the period pipeline. A
// change that alters the physics, the sensors, the command check or the
// period's stages changes it: update the values on purpose, and say why in
// the commit message.
TEST(Determinism, GoldenHashOfTheFixedScenario) {
  const uint64_t serial = goldenScenarioHash(sim::Mode::Serial, 1);
  const uint64_t pipelined = goldenScenarioHash(sim::Mode::Pipelined, 1);
  std::printf("golden scenario: serial %016llx, pipelined %016llx\n",
              static_cast<unsigned long long>(serial), static_cast<unsigned long long>(pipelined));
  EXPECT_EQ(serial, 0x481d68a3a1293632ull);
  EXPECT_EQ(pipelined, 0x2252ca2cfdaf9be1ull);
  EXPECT_EQ(goldenScenarioHash(sim::Mode::Serial, 3), serial);  // any solver thread count
}
