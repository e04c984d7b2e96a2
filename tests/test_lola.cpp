// The LoLA endpoint end to end: real Unix sockets, the real client process
// written for the tests (strict on every sensor map), real Bullet. A joint
// follows its command, stiffness 0 collapses the robot, the chest button is
// seen, the same client and seed give the same state, and no client fault
// stops the simulation or moves the robot.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "simsoccer/lola/endpoint.hpp"
#include "simsoccer/match/agent_process.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

world::Scenario lolaScenario() {
  world::Scenario s = test::scenario(2);
  s.physics.dt = 0.004;
  s.physics.control_period = lola::kCycleSeconds;
  return s;
}

// One LoLA robot (robot 0) and one holding still, and the client process.
struct Rig {
  test::TempDir dir{"lola"};
  world::World world{lolaScenario()};
  sim::Simulation sim{world};
  lola::Endpoint endpoint;
  std::unique_ptr<match::ChildProcess> client;

  explicit Rig(const std::vector<std::string>& client_args, bool lockstep = true)
      : endpoint(world, config(dir.path(), lockstep)) {
    sim.addSource(endpoint);
    std::vector<std::string> args = {SIMSOCCER_LOLA_CLIENT, "--socket",
                                     (dir.path() / "robot.sock").string()};
    args.insert(args.end(), client_args.begin(), client_args.end());
    client = std::make_unique<match::ChildProcess>(args);
    EXPECT_TRUE(endpoint.waitForClients(10.0)) << "the client never connected";
  }
  static lola::EndpointConfig config(const std::filesystem::path& dir, bool lockstep) {
    lola::EndpointConfig c;
    lola::RobotSocket r;
    r.robot = 0;
    r.socket = dir / "robot.sock";
    r.identity = lola::defaultIdentity(1, 1);
    c.robots.push_back(r);
    c.lockstep = lockstep;
    c.answer_timeout = 0.5;
    return c;
  }
  void run(int periods) {
    for (int i = 0; i < periods; ++i) sim.period();
  }
  // Runs until the client exits; its exit status.
  int finish(int max_periods = 2000) {
    for (int i = 0; i < max_periods && client->running(); ++i) sim.period();
    for (int i = 0; i < 200 && client->running(); ++i) usleep(10000);
    return client->running() ? -1 : client->exitStatus();
  }
  double headYaw() const {
    return world.jointPosition(0, world.robot(0).model->actuators[0].index);
  }
};

}  // namespace

TEST(LolaEndpoint, AJointFollowsItsCommandAndEveryMapPassesTheStrictClient) {
  Rig rig({"--joint", "HeadYaw=0.6", "--cycles", "150"});
  EXPECT_EQ(rig.finish(), 0) << "the strict client refused a sensor map";
  EXPECT_NEAR(rig.headYaw(), 0.6, 0.03);
  EXPECT_TRUE(rig.world.isStanding(0));
  const lola::RobotLolaStats s = rig.endpoint.stats(0);
  EXPECT_EQ(s.sessions, 1u);
  EXPECT_GE(s.packets_sent, 150u);
  EXPECT_EQ(s.packets_dropped, 0u);
  EXPECT_EQ(s.missed, 0u);
  EXPECT_EQ(s.refused, 0u);
  EXPECT_EQ(s.answered, 150u);
  EXPECT_EQ(rig.endpoint.actuators(0).chest[2], 1.0f);  // the client's blue chest
  EXPECT_EQ(rig.sim.commandStats(0).accepted, 150u);
}

TEST(LolaEndpoint, StiffnessZeroMakesTheRobotCollapse) {
  Rig rig({"--stiffness", "0", "--cycles", "250"});
  EXPECT_EQ(rig.finish(), 0);
  EXPECT_FALSE(rig.world.isStanding(0));
  EXPECT_TRUE(rig.world.isStanding(1));  // the other robot, holding its stance
  EXPECT_LT(rig.world.torsoPose(0).translation().z(), 0.2);
}

TEST(LolaEndpoint, TheClientSeesTheChestButtonPressed) {
  Rig rig({"--expect-chest", "--cycles", "200"});
  rig.run(20);
  rig.world.setTouch(0, world::Touch::ChestButton, true);
  EXPECT_EQ(rig.finish(), 0) << "the client did not see the chest button";
}

TEST(LolaEndpoint, SameClientSameSeedSameFinalState) {
  std::vector<uint64_t> hashes;
  for (int run = 0; run < 2; ++run) {
    Rig rig({"--mode", "partial", "--joint", "LShoulderPitch=0.4", "--cycles", "120"});
    EXPECT_EQ(rig.finish(), 0);
    hashes.push_back(rig.world.stateHash());
    EXPECT_EQ(rig.endpoint.stats(0).missed, 0u);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
}

TEST(LolaEndpoint, PartialSplitAndDoubleMapsAreMerged) {
  Rig rig({"--mode", "partial", "--joint", "HeadYaw=-0.5", "--cycles", "100"});
  EXPECT_EQ(rig.finish(), 0);
  EXPECT_NEAR(rig.headYaw(), -0.5, 0.03);
  const lola::RobotLolaStats s = rig.endpoint.stats(0);
  EXPECT_GE(s.maps, 199u);  // a Position map and an LED map per cycle
  EXPECT_EQ(s.bad_maps, 0u);
  EXPECT_EQ(rig.endpoint.actuators(0).chest[0], 1.0f);  // the second map's red
}

// Each fault once, 30 cycles in: the client must get through 90 cycles, the
// robot keeps standing with its head where the client put it, the fault is counted.
class LolaFault : public ::testing::TestWithParam<std::string> {};

TEST_P(LolaFault, NeverStopsTheSimulationOrMovesTheRobot) {
  const std::string mode = GetParam();
  Rig rig({"--mode", mode, "--after", "30", "--joint", "HeadYaw=0.3", "--cycles", "90"});
  EXPECT_EQ(rig.finish(), 0) << mode;
  rig.run(10);  // and on without a client
  EXPECT_TRUE(rig.world.isStanding(0)) << mode;
  EXPECT_NEAR(rig.headYaw(), 0.3, 0.03) << mode;
  const lola::RobotLolaStats s = rig.endpoint.stats(0);
  EXPECT_GE(s.no_client, 10u);
  if (mode == "garbage" || mode == "huge") {
    EXPECT_EQ(s.stream_errors, 1u) << mode;
    EXPECT_EQ(s.sessions, 2u) << mode;
  } else if (mode == "nan") {
    EXPECT_EQ(s.refused, 1u);
    EXPECT_EQ(rig.sim.commandStats(0).rejected, 1u);
  } else if (mode == "unknown") {
    EXPECT_EQ(s.unknown_keys, 2u * 90u);
  } else if (mode == "silent") {
    EXPECT_GE(s.missed, 30u);  // lockstep waited for the first few, then stopped waiting
    EXPECT_EQ(s.sessions, 1u);
  } else if (mode == "probe") {
    EXPECT_EQ(s.sessions, 2u);
  }
}

INSTANTIATE_TEST_SUITE_P(Faults, LolaFault,
                         ::testing::Values("garbage", "nan", "huge", "unknown", "silent", "probe"));

TEST(LolaEndpoint, ARobotThatIsNoNaoOrAWrongPeriodIsRefusedWithTheReason) {
  test::TempDir dir("lola_refused");
  world::World ten_ms(test::scenario(1));  // 10 ms control period
  try {
    lola::Endpoint e(ten_ms, Rig::config(dir.path(), true));
    FAIL() << "a 10 ms control period was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("control_period"), std::string::npos) << e.what();
  }
  world::World ok(lolaScenario());
  lola::EndpointConfig c = Rig::config(dir.path(), true);
  c.robots[0].socket = dir.path() / std::string(120, 's');
  try {
    lola::Endpoint e(ok, c);
    FAIL() << "a 120-character socket path was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at most"), std::string::npos) << e.what();
  }
}

// Two team binaries at once, each in its own mount namespace through
// `simsoccer lola-run`, each finds its own robot at /tmp/robocup.
TEST(LolaRun, TwoBinariesAtOnceEachSeeTheirOwnRobotAtTmpRobocup) {
  test::TempDir dir("lola_run");
  world::World world(lolaScenario());
  sim::Simulation sim(world);
  lola::EndpointConfig c;
  for (world::RobotId r = 0; r < 2; ++r) {
    lola::RobotSocket rs;
    rs.robot = r;
    rs.socket = dir.path() / ("robot_" + std::to_string(r) + ".sock");
    rs.identity = lola::defaultIdentity(5, static_cast<int>(r) + 1);
    c.robots.push_back(rs);
  }
  lola::Endpoint endpoint(world, c);
  sim.addSource(endpoint);
  std::vector<std::unique_ptr<match::ChildProcess>> clients;
  for (world::RobotId r = 0; r < 2; ++r)
    clients.push_back(std::make_unique<match::ChildProcess>(std::vector<std::string>{
        SIMSOCCER_BIN, "lola-run", "--socket", c.robots[r].socket.string(), "--",
        SIMSOCCER_LOLA_CLIENT, "--expect-id", c.robots[r].identity.body_id, "--cycles", "50"}));
  ASSERT_TRUE(endpoint.waitForClients(20.0)) << "the clients did not connect through lola-run";
  for (int i = 0; i < 500 && (clients[0]->running() || clients[1]->running()); ++i) sim.period();
  for (auto& client : clients) {
    for (int i = 0; i < 200 && client->running(); ++i) usleep(10000);
    EXPECT_FALSE(client->running());
    EXPECT_EQ(client->exitStatus(), 0) << "a client saw another robot, or none";
  }
  EXPECT_EQ(endpoint.stats(0).answered, 50u);
  EXPECT_EQ(endpoint.stats(1).answered, 50u);
}
