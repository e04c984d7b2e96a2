// The LoLA endpoint end to end: real Unix sockets, the real client process
// written for the tests (strict on every sensor map), real Bullet. A joint
// follows its command, stiffness 0 collapses the robot, the chest button is
// seen, the same client and seed give the same state, and no client fault
// stops the simulation or moves the robot.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "simsoccer/lola/endpoint.hpp"
#include "simsoccer/lola/field_network.hpp"
#include "simsoccer/lola/image_stream.hpp"
#include "simsoccer/match/agent_process.hpp"
#include "simsoccer/referee/gamecontroller_link.hpp"
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

  explicit Rig(const std::vector<std::string>& client_args, bool lockstep = true,
               double reconnect_timeout = 0.0)
      : endpoint(world, config(dir.path(), lockstep, reconnect_timeout)) {
    sim.addSource(endpoint);
    std::vector<std::string> args = {SIMSOCCER_LOLA_CLIENT, "--socket",
                                     (dir.path() / "robot.sock").string()};
    args.insert(args.end(), client_args.begin(), client_args.end());
    client = std::make_unique<match::ChildProcess>(args);
    EXPECT_TRUE(endpoint.waitForClients(10.0)) << "the client never connected";
  }
  static lola::EndpointConfig config(const std::filesystem::path& dir, bool lockstep,
                                     double reconnect_timeout = 0.0) {
    lola::EndpointConfig c;
    lola::RobotSocket r;
    r.robot = 0;
    r.socket = dir / "robot.sock";
    r.identity = lola::defaultIdentity(1, 1);
    c.robots.push_back(r);
    c.lockstep = lockstep;
    c.answer_timeout = 0.5;
    c.reconnect_timeout = reconnect_timeout;
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

// Robots 0 and 1 as team 5's players 1 and 2, sockets in `dir`.
lola::EndpointConfig teamFiveConfig(const std::filesystem::path& dir) {
  lola::EndpointConfig c;
  for (world::RobotId r = 0; r < 2; ++r) {
    lola::RobotSocket rs;
    rs.robot = r;
    rs.socket = dir / ("robot_" + std::to_string(r) + ".sock");
    rs.identity = lola::defaultIdentity(5, static_cast<int>(r) + 1);
    c.robots.push_back(rs);
  }
  return c;
}

}  // namespace

// Each map carries the next cycle counter in Battery[3], as under the Webots LoLA controller.
TEST(LolaEndpoint, AJointFollowsItsCommandAndEveryMapPassesTheStrictClient) {
  Rig rig({"--joint", "HeadYaw=0.6", "--cycles", "150", "--expect-ticks"});
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
    Rig rig({"--mode", "partial", "--joint", "LShoulderPitch=0.4", "--cycles", "121"});
    // Exactly the periods the client answers (when its process is seen to
    // exit after that depends on the machine's load).
    rig.run(120);
    hashes.push_back(rig.world.stateHash());
    EXPECT_EQ(rig.endpoint.stats(0).missed, 0u);
    EXPECT_EQ(rig.endpoint.stats(0).answered, 120u);
    EXPECT_EQ(rig.finish(), 0);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
}

TEST(LolaEndpoint, PartialSplitAndDoubleMapsAreMerged) {
  Rig rig({"--mode", "partial", "--joint", "HeadYaw=-0.5", "--cycles", "100"});
  EXPECT_EQ(rig.finish(), 0);
  EXPECT_NEAR(rig.headYaw(), -0.5, 0.03);
  const lola::RobotLolaStats s = rig.endpoint.stats(0);
  // A full map first, then a Position map and an LED map per cycle. The last cycle's LED map
  // comes after its answer: whether a period reads it before the client is seen to exit
  // depends on the machine's load (with three simulations running beside it on 2 cores it
  // did in 10 of 10 runs, alone in none of 8).
  EXPECT_TRUE(s.maps == 198u || s.maps == 199u) << s.maps;
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
  EXPECT_GE(s.no_client, 9u);  // (the first may still take the client's last answer)
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

// B-Human's binary reads one map for the body id, closes the socket and connects again when
// it has booted (here 1 s later): lockstep waits for it (up to the reconnect timeout), so the
// robot misses no period of the game; without the wait the simulation ran on at its own speed
// meanwhile, and the robot stood through the kick-off.
TEST(LolaEndpoint, LockstepWaitsForABinaryThatReconnectsAsItBoots) {
  Rig rig({"--mode", "probe", "--probe-gap", "1.0", "--joint", "HeadYaw=0.3", "--cycles", "80"},
          true, 3.0);
  rig.run(60);  // the client is there through all of them
  lola::RobotLolaStats s = rig.endpoint.stats(0);
  EXPECT_EQ(s.sessions, 2u);
  EXPECT_EQ(s.no_client, 0u);
  EXPECT_EQ(s.missed, 0u);
  EXPECT_GE(s.answered, 58u);
  EXPECT_NEAR(rig.headYaw(), 0.3, 0.03);
  // Gone for good (it exits after its cycles): waited for once, 3 s, then the periods run on
  // without it.
  const auto before = std::chrono::steady_clock::now();
  while (rig.client->running()) rig.run(1);
  rig.run(20);
  const double waited =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  EXPECT_GE(waited, 2.5);
  EXPECT_LT(waited, 10.0);
  EXPECT_GE(rig.endpoint.stats(0).no_client, 19u);
}

// A binary in a crash loop (reads a map, goes, comes back at once, for ever) is waited for
// three times, then not until it answers a period: the periods run on, none stalled for good.
TEST(LolaEndpoint, ACrashLoopingBinaryIsNotWaitedForForEver) {
  Rig rig({"--mode", "flap", "--cycles", "100000"}, true, 2.0);
  const auto before = std::chrono::steady_clock::now();
  rig.run(50);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  const lola::RobotLolaStats s = rig.endpoint.stats(0);
  std::printf("50 periods in %.2f s: %llu sessions, %llu answered\n", wall,
              static_cast<unsigned long long>(s.sessions),
              static_cast<unsigned long long>(s.answered));
  EXPECT_GT(s.sessions, 3u);
  EXPECT_EQ(s.answered, 0u);
  EXPECT_LT(wall, 30.0);  // each wait ends as it reconnects; at most 2.5 s a period otherwise
  EXPECT_TRUE(rig.world.isStanding(0));
}

// One answer comes after the lockstep timeout: that period is missed, the
// late answer counts for its own cycle, and every later command still
// answers its own cycle (no shift by one).
TEST(LolaEndpoint, ALateAnswerDoesNotShiftTheLaterOnes) {
  Rig rig({"--mode", "late", "--after", "30", "--ramp", "--cycles", "61"});
  std::vector<double> applied;  // HeadYaw applied in period p
  for (int p = 0; p < 60; ++p) {
    rig.sim.period();
    applied.push_back(rig.sim.commandApplied(0) ? rig.sim.appliedCommand(0).position[0] : -1.0);
  }
  EXPECT_EQ(rig.finish(), 0);
  EXPECT_EQ(rig.endpoint.stats(0).missed, 1u);
  for (int p = 0; p < 60; ++p) {
    if (p == 30) {
      EXPECT_EQ(applied[static_cast<size_t>(p)], -1.0) << "the late period applies nothing";
    } else {
      EXPECT_NEAR(applied[static_cast<size_t>(p)], 0.001 * p, 1e-4) << "period " << p;
    }
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
  if (!test::bubblewrapWorks()) GTEST_SKIP() << "bubblewrap cannot make a namespace here";
  test::TempDir dir("lola_run");
  world::World world(lolaScenario());
  sim::Simulation sim(world);
  const lola::EndpointConfig c = teamFiveConfig(dir.path());
  lola::Endpoint endpoint(world, c);
  sim.addSource(endpoint);
  // The binary under /tmp, as a team's build may be: the namespace must not hide it.
  const auto client = dir.path() / "team-binary";
  std::filesystem::copy_file(SIMSOCCER_LOLA_CLIENT, client);
  std::vector<std::unique_ptr<match::ChildProcess>> clients;
  for (world::RobotId r = 0; r < 2; ++r)
    clients.push_back(std::make_unique<match::ChildProcess>(std::vector<std::string>{
        SIMSOCCER_BIN, "lola-run", "--socket", c.robots[r].socket.string(), "--", client.string(),
        "--expect-id", c.robots[r].identity.body_id, "--cycles", "50"}));
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

// A LoLA robot's top camera as the Webots LoLA controller streams it: every
// frame read from the TCP stream is the image the camera system rendered for
// that tick (real EGL), and in lockstep it is out before the world steps on.
TEST(LolaImages, AFrameFromTheStreamIsTheImageTheCameraSystemRendered) {
  world::Scenario s = lolaScenario();
  s.cameras.enabled = true;
  s.cameras.top = {true, 64, 48, 30.0};
  s.cameras.bottom = {true, 32, 24, 30.0};
  world::World w(s);
  sim::Simulation simulation(w);
  std::mutex mutex;
  std::map<uint64_t, std::vector<uint8_t>> rendered;  // robot 0's top images by tick
  simulation.addImageSink([&](const world::CameraImage& image) {
    if (image.robot != 0 || image.camera != world::CameraId::Top) return;
    std::lock_guard lock(mutex);
    rendered[image.tick] = image.data;
  });
  lola::ImageStreams streams(simulation, {lola::ImagePorts{0, 0, 0}});
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  const timeval two_seconds{2, 0};  // a stalled stream fails the test instead of hanging it
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &two_seconds, sizeof two_seconds);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(streams.port(0, world::CameraId::Top));
  ::inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  const auto readExactly = [&](uint8_t* out, size_t n) {
    while (n > 0) {
      const ssize_t got = ::recv(fd, out, n, 0);
      if (got <= 0) return false;
      out += got;
      n -= static_cast<size_t>(got);
    }
    return true;
  };
  int frames = 0;
  uint64_t last_tick = 0;
  std::set<uint64_t> seen;
  for (int i = 0; i < 60; ++i) {
    const uint64_t tick = w.controlTick();
    simulation.period();
    // Every frame of this tick is already in the socket (a lockstep period
    // flushes the cameras before it steps): read what is there.
    pollfd p{fd, POLLIN, 0};
    while (::poll(&p, 1, i == 0 ? 200 : 0) > 0) {
      std::array<uint8_t, 16> h{};
      ASSERT_TRUE(readExactly(h.data(), h.size()));
      ASSERT_EQ(std::memcmp(h.data(), "wbimage", 8), 0);
      const uint64_t frame_tick = h[8] | (h[9] << 8);
      EXPECT_EQ(h[10], 0);  // top
      EXPECT_EQ(h[11], 2);  // bytes per pixel
      const int width = h[12] | (h[13] << 8), height = h[14] | (h[15] << 8);
      ASSERT_EQ(width, 64);
      ASSERT_EQ(height, 48);
      std::vector<uint8_t> data(static_cast<size_t>(width * height * 2));
      ASSERT_TRUE(readExactly(data.data(), data.size()));
      EXPECT_LE(frame_tick, tick + 1);  // not from the future
      seen.insert(frame_tick);
      std::lock_guard lock(mutex);
      ASSERT_TRUE(rendered.count(frame_tick)) << "tick " << frame_tick;
      EXPECT_EQ(data, rendered[frame_tick]) << "tick " << frame_tick;
      EXPECT_TRUE(frames == 0 || frame_tick > last_tick);
      last_tick = frame_tick;
      ++frames;
    }
    // Lockstep: every image of a tick up to this period's was written
    // before the world stepped past it.
    std::lock_guard lock(mutex);
    for (const auto& [t, image] : rendered) {
      if (t <= tick) {
        EXPECT_TRUE(seen.count(t)) << "the frame of tick " << t << " was late";
      }
    }
  }
  ::close(fd);
  // 60 periods of 12 ms at 30 fps: about 21 frames, none dropped.
  EXPECT_GE(frames, 18);
  EXPECT_EQ(streams.stats(0, world::CameraId::Top).frames_dropped, 0u);
}

// Two team binaries on the field network, each in its own namespace through
// `simsoccer lola-run --net`: each binds 3838 and its team port for itself,
// receives the simulator's broadcast GameController packets, sends its
// status packet to the simulator, and hears its teammate's broadcast team
// messages, which the simulator counts. Needs root (network namespaces).
TEST(LolaRun, TeamBinariesOnTheFieldNetworkGetTheGameAndTalk) {
  const bool ip = std::filesystem::exists("/usr/sbin/ip") || std::filesystem::exists("/sbin/ip") ||
                  std::filesystem::exists("/bin/ip");
  if (::geteuid() != 0 || !ip || !test::bubblewrapWorks())
    GTEST_SKIP() << "needs root, iproute2 and bubblewrap";
  test::TempDir dir("lola_net");
  lola::FieldNetwork net;
  net.bridge = "sst" + std::to_string(::getpid() % 100000);
  net.prefix = "10.78";
  net.link_prefix = "st";
  lola::FieldBridge bridge(net);
  world::World world(lolaScenario());
  const lola::EndpointConfig c = teamFiveConfig(dir.path());
  lola::Endpoint endpoint(world, c);  // the sockets lola-run binds
  const referee::RuleBook rules =
      referee::loadRuleBook(test::sourceDir() / "configs" / "rules" / "spl.yaml");
  referee::Game game(rules, {referee::TeamSetup{5, 0, 2, 1}, referee::TeamSetup{9, 1, 3, 1}}, 0);
  referee::GameControllerLinkConfig gc;
  gc.address = net.broadcast();
  gc.return_bind = net.hostAddress();
  gc.team_message_bind = net.broadcast();
  gc.team_message_device = net.bridge;  // as a match has it
  referee::GameControllerLink link(gc);
  std::vector<std::unique_ptr<match::ChildProcess>> binaries;
  for (int player = 1; player <= 2; ++player)
    binaries.push_back(std::make_unique<match::ChildProcess>(std::vector<std::string>{
        SIMSOCCER_BIN, "lola-run", "--robot", "5:" + std::to_string(player), "--socket",
        c.robots[static_cast<size_t>(player - 1)].socket.string(), "--net", "--bridge", net.bridge,
        "--prefix", net.prefix, "--", SIMSOCCER_LOLA_CLIENT, "--mode", "gc", "--team-number", "5",
        "--player", std::to_string(player), "--gc-host", net.hostAddress(), "--broadcast",
        // The limited broadcast, as some teams send: counted too (a
        // socket bound to the subnet's broadcast address never got it).
        "255.255.255.255"}));
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while ((binaries[0]->running() || binaries[1]->running()) &&
         std::chrono::steady_clock::now() < until) {
    link.update(game);
    game.advance(0.05);
    usleep(50000);
  }
  link.update(game);
  for (auto& b : binaries) {
    EXPECT_FALSE(b->running());
    EXPECT_EQ(b->exitStatus(), 0);
  }
  EXPECT_TRUE(link.lastReturn(5, 1).has_value()) << "player 1's status did not arrive";
  EXPECT_TRUE(link.lastReturn(5, 2).has_value()) << "player 2's status did not arrive";
  EXPECT_GE(link.teamMessages(5), 2u);
  EXPECT_EQ(link.teamMessages(9), 0u);
  // The namespaces are gone with the binaries.
  EXPECT_FALSE(std::filesystem::exists("/run/netns/" + net.namespaceName(5, 1)));
}
