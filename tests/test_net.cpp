// Agents over DDS, end to end: the simulator's server in this process, real
// simsoccer-agent processes, real Cyclone DDS on loopback.
#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "agent_process.hpp"
#include "gc_reader.hpp"
#include "simsoccer/agents/agent_client.hpp"
#include "simsoccer/net/domain_claim.hpp"
#include "simsoccer/net/robot_keys.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/sim/run_loop.hpp"
#include "test_support.hpp"

extern char** environ;

using namespace simsoccer;
using test::AgentProcess;
using test::runCommand;
using Clock = std::chrono::steady_clock;

namespace {

net::DomainConfig dds(uint32_t domain) {
  net::DomainConfig c;
  c.domain = domain;
  c.config_file = test::sourceDir() / "configs" / "dds" / "loopback.xml";
  return c;
}

// A lockstep server on `domain` waiting up to `command_timeout` s for commands.
net::ServerConfig serverConfig(uint32_t domain,
                               double command_timeout = net::ServerConfig{}.command_timeout) {
  net::ServerConfig cfg;
  cfg.dds = dds(domain);
  cfg.command_timeout = command_timeout;
  return cfg;
}

// An agent in this process claims its robot (in a thread) while the server
// handles claims; true if granted within `timeout` s.
bool claimWhilePolling(net::SimServer& server, agents::AgentClient& agent, double timeout,
                       agents::AgentClient::IfOwned if_owned) {
  std::atomic<bool> answered{false}, granted{false};
  std::thread claimant([&] {
    granted = agent.claim(timeout, if_owned);
    answered = true;
  });
  const auto end = Clock::now() + std::chrono::duration<double>(timeout + 1.0);
  while (!answered && Clock::now() < end) server.poll(0.02);
  claimant.join();
  return granted;
}

world::Scenario teams(int n) {
  world::Scenario s = test::scenario(n);
  return s;
}

double seconds(Clock::time_point a) {
  return std::chrono::duration<double>(Clock::now() - a).count();
}

// simsoccer-agent for robot (0, 1) with `options`: a usage error (exit status
// 2) that names `option`.
void expectAgentUsageError(const std::string& options, const std::string& option) {
  int status = 0;
  const std::string out = runCommand(
      std::string(SIMSOCCER_AGENT_BIN) + " --team 0 --player 1 " + options + " 2>&1", status);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << out;
  EXPECT_NE(out.find(option), std::string::npos) << out;
}

}  // namespace

TEST(Net, RoundTripAgentDrivesItsRobot) {
  const uint32_t domain = 101;
  world::World w(teams(1));
  net::ServerConfig cfg = serverConfig(domain);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  AgentProcess agent(domain, 0, 1);
  ASSERT_TRUE(server.waitForOwners(1, 20.0)) << "the agent did not claim its robot";
  const int head = w.robot(0).model->body->jointIndex("HeadPitch");
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i < 200; ++i) {  // 2 s: a whole nod
    simulation.period();
    const double q = w.jointPosition(0, head);
    lo = std::min(lo, q);
    hi = std::max(hi, q);
  }
  const auto& st = server.stats(0);
  std::printf("accepted %llu, missed %llu, rejected %llu; head pitch %.3f..%.3f\n",
              (unsigned long long)st.accepted, (unsigned long long)st.missed,
              (unsigned long long)st.rejected, lo, hi);
  EXPECT_GE(st.accepted, 195u);
  EXPECT_EQ(st.rejected, 0u);
  EXPECT_GT(hi - lo, 0.3);  // the nod commanded over DDS moved the head
  EXPECT_TRUE(w.isStanding(0));
}

TEST(Net, LockstepIsDeterministicWithAgentProcesses) {
  auto run = [](uint32_t domain) {
    world::World w(teams(5));
    net::ServerConfig cfg = serverConfig(domain, 5.0);  // a slow machine must not change the result
    sim::Simulation simulation(w);
    net::SimServer server(simulation, cfg);
    std::vector<std::unique_ptr<AgentProcess>> agents;
    for (world::RobotId r = 0; r < w.robotCount(); ++r)
      agents.push_back(std::make_unique<AgentProcess>(domain, w.robot(r).team, w.robot(r).number));
    EXPECT_TRUE(server.waitForOwners(5, 30.0));
    for (int i = 0; i < 500; ++i) simulation.period();
    uint64_t missed = 0;
    for (world::RobotId r = 0; r < w.robotCount(); ++r) missed += server.stats(r).missed;
    EXPECT_EQ(missed, 0u);
    return w.stateHash();
  };
  const uint64_t a = run(102), b = run(103);
  std::printf("final state hashes %016llx %016llx\n", (unsigned long long)a, (unsigned long long)b);
  EXPECT_EQ(a, b);
}

TEST(Net, SecondClaimantIsRefusedAndCannotMoveTheRobot) {
  const uint32_t domain = 104;
  world::World w(teams(1));
  net::ServerConfig cfg = serverConfig(domain, 2.0);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  AgentProcess owner(domain, 0, 1);
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  // An intruder in this process (its own participant) claims the same robot.
  agents::AgentClient intruder(dds(domain), 0, 1);
  EXPECT_FALSE(claimWhilePolling(server, intruder, 5.0, agents::AgentClient::IfOwned::Refuse));
  EXPECT_FALSE(intruder.ownsRobot());
  EXPECT_GT(intruder.status().refused, 0u);  // told so, in the robot's partition
  // It sends head-yaw commands for the coming ticks; the owner keeps HeadYaw at 0.
  std::vector<float> pos(25, 0.0f), stiff(25, 1.0f);
  pos[0] = 1.5f;  // HeadYaw
  const uint64_t refused_before = server.stats(0).refused;
  for (int i = 0; i < 100; ++i) {
    const uint64_t tick = w.controlTick();
    intruder.send(tick, pos, stiff);
    simulation.period();
  }
  std::printf("refused %llu commands, head yaw %.3f\n",
              (unsigned long long)(server.stats(0).refused - refused_before),
              w.jointPosition(0, 0));
  EXPECT_GT(server.stats(0).refused, refused_before + 50);
  EXPECT_NEAR(w.jointPosition(0, 0), 0.0, 0.05);
}

// A match that starts its agents reserves their robots (net/robot_keys.hpp):
// without the robot's key nobody claims or moves it, not with the other
// robot's key, not while its agent is down; the agent ignores a rogue's game
// states and frames.
TEST(Net, AReservedRobotAnswersOnlyItsKey) {
  const uint32_t domain = 150;
  world::World w(teams(2));
  net::ServerConfig cfg = serverConfig(domain, 0.05);
  const net::MatchSecret secret = net::newMatchSecret();
  cfg.reserve = secret;
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  simsoccer_msg_GameState playing{};
  playing.state = 3;  // PLAYING
  server.setGameState(playing);
  const auto keyVariable = [&](int team, int player) {
    return std::string(net::kRobotKeyVariable) + "=" +
           net::toHex(net::robotKey(secret, team, player));
  };
  auto owner = std::make_unique<AgentProcess>(domain, 0, 1, std::vector<std::string>{},
                                              std::vector<std::string>{keyVariable(0, 1)});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  // Strangers: no key, the other robot's key, a made-up key.
  agents::AgentClient no_key(dds(domain), 0, 1);
  agents::AgentClient other_key(dds(domain), 0, 1, net::robotKey(secret, 1, 1));
  agents::AgentClient made_up(dds(domain), 0, 1, net::robotKey(net::newMatchSecret(), 0, 1));
  const auto refuse = agents::AgentClient::IfOwned::Refuse;
  for (agents::AgentClient* c : {&no_key, &other_key, &made_up})
    EXPECT_FALSE(claimWhilePolling(server, *c, 3.0, refuse));
  EXPECT_GE(server.stats(0).unauthorised, 3u);
  // Its agent dies, and the launcher frees the robot (as a match does): still
  // nobody without the key takes it, and 10,000 of their commands move nothing.
  owner.reset();
  ASSERT_TRUE(server.releaseRobot(0));
  for (agents::AgentClient* c : {&no_key, &other_key, &made_up})
    EXPECT_FALSE(claimWhilePolling(server, *c, 1.0, agents::AgentClient::IfOwned::WaitForRelease));
  EXPECT_FALSE(server.stats(0).owned);
  std::vector<float> pos(25, 0.0f), stiff(25, 1.0f);
  pos[0] = 1.5f;  // HeadYaw
  const uint64_t accepted_before = server.stats(0).accepted;
  const uint64_t refused_before = server.stats(0).refused;
  for (int i = 0; i < 10000; ++i) {
    agents::AgentClient* c = i % 3 == 0 ? &no_key : i % 3 == 1 ? &other_key : &made_up;
    c->send(w.controlTick(), pos, stiff);
    if (i % 100 == 99) simulation.period();
  }
  for (int i = 0; i < 20; ++i) simulation.period();
  const uint64_t refused = server.stats(0).refused - refused_before;
  std::printf(
      "unauthorised claims %llu; of 10000 strangers' commands %llu accepted, %llu refused\n",
      (unsigned long long)server.stats(0).unauthorised,
      (unsigned long long)(server.stats(0).accepted - accepted_before),
      (unsigned long long)refused);
  EXPECT_EQ(server.stats(0).accepted, accepted_before);
  EXPECT_GE(refused, 9000u);  // the rest may still be in flight: none applied
  EXPECT_NEAR(w.jointPosition(0, 0), 0.0, 0.05);
  // Its restarted agent, with the key, gets it back at once.
  AgentProcess again(domain, 0, 1, {}, {keyVariable(0, 1)});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  const uint64_t before = server.stats(0).accepted;
  for (int i = 0; i < 50; ++i) simulation.period();
  EXPECT_GE(server.stats(0).accepted, before + 45);
  // An agent in this process holding robot (1, 1)'s key: it learns which
  // participant is the simulator, and a rogue's game state and frames in its
  // partition do not reach it.
  agents::AgentClient mine(dds(domain), 1, 1, net::robotKey(secret, 1, 1));
  ASSERT_TRUE(claimWhilePolling(server, mine, 10.0, refuse));
  EXPECT_TRUE(mine.knowsSimulator());
  {
    simsoccer_msg_GameState g{};
    EXPECT_TRUE(mine.gameState(g)) << "before rogue";
    EXPECT_TRUE(mine.waitForGameState(2.0)) << "before rogue";
  }
  net::Participant rogue(dds(domain));
  net::Writer<simsoccer_msg_GameState> rogue_game(rogue, simsoccer_msg_GameState_desc,
                                                  "simsoccer_GameState", {true, 1, true, ""});
  net::Writer<simsoccer_msg_SensorFrame> rogue_frames(
      rogue, simsoccer_msg_SensorFrame_desc, "simsoccer_SensorFrame",
      {true, 1, false, net::robotPartitionName(1, 1)});
  simsoccer_msg_GameState finished{};
  finished.state = 4;  // FINISHED
  simsoccer_msg_SensorFrame fake{};
  fake.team = 1;
  fake.player = 1;
  fake.tick = 1u << 30;
  const auto t0 = Clock::now();
  while (mine.foreignSamples() < 100 && seconds(t0) < 20.0) {
    rogue_game.write(finished);
    rogue_frames.write(fake);
    simulation.period();  // the simulator's own frames, and its game state at 2 Hz
    simsoccer_msg_GameState g{};
    EXPECT_TRUE(mine.gameState(g));
    EXPECT_EQ(g.state, 3);
    simsoccer_msg_SensorFrame f{};
    if (mine.receive(f, 0.05)) {
      EXPECT_LT(f.tick, 1u << 30);
    }
  }
  EXPECT_GE(mine.foreignSamples(), 100u);
}

TEST(Net, KilledAgentReleasesItsRobotAndARestartReclaimsIt) {
  const uint32_t domain = 105;
  world::World w(teams(2));
  net::ServerConfig cfg = serverConfig(domain, 0.05);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  // A 2 s lease (--lease; the default is 5 s): the robot is free about 2 s after.
  auto a = std::make_unique<AgentProcess>(domain, 0, 1, std::vector<std::string>{"--lease", "2"});
  AgentProcess b(domain, 1, 1);
  ASSERT_TRUE(server.waitForOwners(2, 20.0));
  for (int i = 0; i < 50; ++i) simulation.period();
  a->kill();  // SIGKILL: no goodbye on DDS, the lease has to expire
  const auto t0 = Clock::now();
  while (server.stats(0).owned && seconds(t0) < 10.0) simulation.period();
  const double released_after = seconds(t0);
  EXPECT_FALSE(server.stats(0).owned);
  EXPECT_GT(released_after, 1.0);  // the lease expired: nothing told the simulator sooner
  EXPECT_LT(released_after, 5.0);  // about 2 s measured: the writers unmatch, no hang
  const uint64_t b_accepted = server.stats(1).accepted;
  for (int i = 0; i < 50; ++i) simulation.period();
  EXPECT_GE(server.stats(1).accepted, b_accepted + 45);  // the other robot kept going
  EXPECT_TRUE(w.isStanding(0));                          // released: holds its pose
  // Restarted, it claims the robot again and drives it.
  AgentProcess again(domain, 0, 1);
  ASSERT_TRUE(server.waitForOwners(2, 20.0));
  const uint64_t before = server.stats(0).accepted;
  for (int i = 0; i < 100; ++i) simulation.period();
  std::printf("released %.2f s after SIGKILL; after restart accepted %llu commands\n",
              released_after, (unsigned long long)(server.stats(0).accepted - before));
  EXPECT_GE(server.stats(0).accepted, before + 90);
}

// An agent restarted right after a crash, while its robot is still owned by
// the dead process, gets it back when that lease runs out (claim() waits).
TEST(Net, AnAgentRestartedAtOnceGetsItsRobotBackWhenTheLeaseRunsOut) {
  const uint32_t domain = 122;
  world::World w(teams(1));
  sim::Simulation simulation(w);
  net::SimServer server(simulation, serverConfig(domain, 0.05));
  auto crashed =
      std::make_unique<AgentProcess>(domain, 0, 1, std::vector<std::string>{"--lease", "2"});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  for (int i = 0; i < 20; ++i) simulation.period();
  crashed->kill();
  AgentProcess restarted(domain, 0, 1);  // claims while the robot is still owned
  const auto t0 = Clock::now();
  bool released = false;
  while (seconds(t0) < 15.0 && !(released && server.stats(0).owned)) {
    simulation.period();
    released = released || !server.stats(0).owned;
  }
  ASSERT_TRUE(released);
  ASSERT_TRUE(server.stats(0).owned) << "the restarted agent did not get its robot back";
  const double back_after = seconds(t0);
  const uint64_t before = server.stats(0).accepted;
  for (int i = 0; i < 60; ++i) simulation.period();
  EXPECT_GE(server.stats(0).accepted, before + 55);  // it drives the robot
  EXPECT_TRUE(restarted.running());
  std::printf("the restarted agent had its robot back %.2f s after the crash\n", back_after);
}

// A launcher that saw its agent process exit frees the robot at once: lockstep
// stops waiting for it, and another agent can claim it.
TEST(Net, ReleasedRobotIsNotWaitedForAndCanBeClaimedAgain) {
  const uint32_t domain = 121;
  world::World w(teams(1));
  sim::Simulation simulation(w);
  net::SimServer server(simulation, serverConfig(domain, 2.0));
  AgentProcess stalled(domain, 0, 1, {"--mode", "stall", "--stall-after", "20"});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  for (int i = 0; i < 20; ++i) simulation.period();
  EXPECT_EQ(server.stats(0).missed, 0u);
  EXPECT_TRUE(server.releaseRobot(0));
  EXPECT_FALSE(server.releaseRobot(0));  // nobody owns it now
  EXPECT_FALSE(server.stats(0).owned);
  const auto t0 = Clock::now();
  for (int i = 0; i < 10; ++i) simulation.period();
  EXPECT_LT(seconds(t0), 1.0);  // not 10 x the 2 s timeout
  EXPECT_EQ(server.stats(0).missed, 0u);
  EXPECT_TRUE(w.isStanding(0));  // released: holds its pose
  agents::AgentClient again(dds(domain), 0, 1);
  EXPECT_TRUE(claimWhilePolling(server, again, 10.0, agents::AgentClient::IfOwned::WaitForRelease));
  EXPECT_TRUE(server.stats(0).owned);
}

// configs/dds/lan.xml, for agents on other machines: discovery by multicast
// on a network interface, data by unicast. The same loop as on loopback, with
// the simulator and the agent on this machine (its own address).
TEST(Net, TheLanConfigurationFindsTheAgentOnANetworkInterface) {
  const auto interface_address = test::multicastInterfaceAddress();
  if (!interface_address) GTEST_SKIP() << "no network interface that can multicast";
  const uint32_t domain = 125;
  test::SpdpMulticastListener announcements(domain, *interface_address);
  ASSERT_TRUE(announcements.ok());
  const std::string lan = (test::sourceDir() / "configs" / "dds" / "lan.xml").string();
  world::World w(teams(1));
  net::ServerConfig cfg = serverConfig(domain);
  cfg.dds.config_file = lan;
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  AgentProcess agent(domain, 0, 1, {}, {}, lan);
  ASSERT_TRUE(server.waitForOwners(1, 20.0)) << "the agent did not claim its robot";
  for (int i = 0; i < 100; ++i) simulation.period();
  const auto& st = server.stats(0);
  EXPECT_GE(st.accepted, 95u);
  EXPECT_EQ(st.missed, 0u);
  // The participants announced themselves by multicast on the network
  // interface (with loopback.xml: none, unicast to 127.0.0.1 only).
  EXPECT_GE(announcements.received(), 2);
}

namespace {

// The kernel's count of datagrams dropped at the IPv4 UDP socket bound to `port`
// (/proc/net/udp's last column), or -1 if there is none.
long udpDrops(uint16_t port) {
  std::ifstream table("/proc/net/udp");
  std::string line;
  std::getline(table, line);  // header
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot, local, field;
    fields >> slot >> local;
    if (std::stoul(local.substr(local.find(':') + 1), nullptr, 16) != port) continue;
    while (fields >> field) {
    }
    return std::stol(field);  // the last field
  }
  return -1;
}

// `count` datagrams from a socket bound to `from` to `to`:`port`.
void sendDatagrams(in_addr from, in_addr to, uint16_t port, int count) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_addr = from;
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&at), sizeof at), 0);
  at.sin_addr = to;
  at.sin_port = htons(port);
  const char rtps[] = "RTPS not really";
  for (int i = 0; i < count; ++i)
    sendto(fd, rtps, sizeof rtps, 0, reinterpret_cast<sockaddr*>(&at), sizeof at);
  close(fd);
}

}  // namespace

// Cyclone binds its receive sockets to every address; with loopback.xml a domain's are
// filtered to datagrams from 127.0.0.0/8 (net/src/dds.cpp). Datagrams sent to them from
// this machine's network address are dropped by the kernel (its drop count rises by each);
// datagrams from loopback are not, and a participant on loopback is still matched.
TEST(Net, TheLoopbackConfigurationHearsNothingFromOtherAddresses) {
  const auto network_address = test::multicastInterfaceAddress();
  if (!network_address) GTEST_SKIP() << "no network interface";
  const uint32_t domain = 161;
  net::Participant listener(dds(domain));
  ASSERT_EQ(listener.loopbackOnlyPorts().size(), 2u) << "discovery and data unicast ports";
  // A configuration that sends on a network interface is left alone.
  net::DomainConfig on_network = dds(162);
  on_network.config_file = test::sourceDir() / "configs" / "dds" / "lan.xml";
  EXPECT_TRUE(net::Participant(on_network).loopbackOnlyPorts().empty());

  in_addr loopback{};
  loopback.s_addr = htonl(INADDR_LOOPBACK);
  for (const uint16_t port : listener.loopbackOnlyPorts()) {
    const long before = udpDrops(port);
    ASSERT_GE(before, 0) << "no socket on port " << port;
    sendDatagrams(*network_address, *network_address, port, 10);
    sendDatagrams(loopback, loopback, port, 10);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    EXPECT_EQ(udpDrops(port) - before, 10) << "port " << port;
  }

  // A neighbour on loopback (the same RTPS domain: Cyclone's ExternalDomainId) is matched.
  net::DomainConfig on_loopback = dds(163);
  on_loopback.external_domain = domain;
  net::Participant neighbour(on_loopback);
  dds_qos_t* q = net::makeQos({});
  const net::Entity reader(net::check(
      dds_create_reader(listener.get(), listener.topic(simsoccer_msg_SimClock_desc, "Neighbour"), q,
                        nullptr),
      "create reader"));
  const net::Entity writer(net::check(
      dds_create_writer(neighbour.get(), neighbour.topic(simsoccer_msg_SimClock_desc, "Neighbour"),
                        q, nullptr),
      "create writer"));
  dds_delete_qos(q);
  dds_subscription_matched_status_t matched{};
  const auto start = Clock::now();
  while (matched.current_count == 0 && seconds(start) < 10.0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    net::check(dds_get_subscription_matched_status(reader.get(), &matched), "matched status");
  }
  EXPECT_EQ(matched.current_count, 1u) << "the loopback neighbour was not matched";
}

TEST(Net, ATakeIntoKeptSamplesCarriesEachSamplesOwnSequences) {
  // Frames taken into the samples a reader keeps (the agents' path): each take sees its own
  // frame's sightings, however many the one before had (more, fewer, none).
  net::Participant sim(dds(171));
  net::Participant agent(dds(171));
  const std::string partition = net::robotPartitionName(0, 1);
  net::Writer<simsoccer_msg_SensorFrame> writer(sim, simsoccer_msg_SensorFrame_desc, "KeptFrames",
                                                {true, 1, false, partition});
  net::Reader<simsoccer_msg_SensorFrame> reader(agent, simsoccer_msg_SensorFrame_desc, "KeptFrames",
                                                {true, 1, false, partition});
  dds_publication_matched_status_t matched{};
  for (const auto start = Clock::now(); matched.current_count == 0 && seconds(start) < 10.0;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    net::check(dds_get_publication_matched_status(writer.get(), &matched), "matched status");
  }
  ASSERT_EQ(matched.current_count, 1u);
  uint64_t tick = 0;
  for (const uint32_t seen : {3u, 1u, 0u, 21u, 2u}) {
    ++tick;
    std::vector<simsoccer_msg_PerceivedObject> robots(seen);
    for (uint32_t i = 0; i < seen; ++i) robots[i].position[0] = static_cast<float>(100 * tick + i);
    simsoccer_msg_SensorFrame f{};
    f.team = 0;
    f.player = 1;
    f.tick = tick;
    f.perception.robots._buffer = robots.data();
    f.perception.robots._length = f.perception.robots._maximum = seen;
    writer.write(f);
    int taken = 0;
    for (const auto start = Clock::now(); taken == 0 && seconds(start) < 5.0;
         std::this_thread::sleep_for(std::chrono::milliseconds(1)))
      taken =
          reader.takeReusing([&](const simsoccer_msg_SensorFrame& got, const dds_sample_info_t&) {
            EXPECT_EQ(got.tick, tick);
            ASSERT_EQ(got.perception.robots._length, seen) << "tick " << tick;
            for (uint32_t i = 0; i < seen; ++i)
              EXPECT_EQ(got.perception.robots._buffer[i].position[0],
                        static_cast<float>(100 * tick + i));
          });
    EXPECT_EQ(taken, 1) << "tick " << tick;
  }
}

TEST(Net, GarbageCommandsAreRejectedAndCounted) {
  const uint32_t domain = 106;
  world::World w(teams(2));
  net::ServerConfig cfg = serverConfig(domain, 2.0);
  // The first refusal per robot is told, with its reason (on the DDS receive thread); the
  // rest are only counted.
  std::mutex told_mutex;
  std::vector<std::string> told;
  cfg.notice = [&](const std::string& line) {
    const std::lock_guard lock(told_mutex);
    told.push_back(line);
  };
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  AgentProcess garbage(domain, 0, 1, {"--mode", "garbage"});
  AgentProcess good(domain, 1, 1);
  ASSERT_TRUE(server.waitForOwners(2, 20.0));
  for (int i = 0; i < 150; ++i) simulation.period();
  const auto& g = server.stats(0);
  std::printf(
      "garbage agent: accepted %llu, rejected %llu; good agent: accepted %llu rejected %llu\n",
      (unsigned long long)g.accepted, (unsigned long long)g.rejected,
      (unsigned long long)server.stats(1).accepted, (unsigned long long)server.stats(1).rejected);
  EXPECT_GE(g.rejected, 140u);  // one bad command per tick, of every kind in turn
  EXPECT_GE(g.accepted, 145u);  // its valid commands still count
  EXPECT_EQ(server.stats(1).rejected, 0u);
  EXPECT_GE(server.stats(1).accepted, 145u);
  EXPECT_TRUE(w.isStanding(0));
  EXPECT_TRUE(w.isStanding(1));
  for (int j = 0; j < static_cast<int>(w.robot(0).model->body->joints.size()); ++j)
    EXPECT_TRUE(std::isfinite(w.jointPosition(0, j)));
  const std::lock_guard lock(told_mutex);
  ASSERT_EQ(told.size(), 1u);  // robot 0 alone, once
  EXPECT_EQ(told[0].rfind("team 0 player 1: its owner's command refused (", 0), 0u) << told[0];
  EXPECT_NE(told[0].find("); later refusals are counted, not told"), std::string::npos) << told[0];
}

TEST(Net, LockstepTimeoutBoundsAStalledAgent) {
  const uint32_t domain = 107;
  world::World w(teams(1));
  net::ServerConfig cfg = serverConfig(domain, 0.05);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  AgentProcess stall(domain, 0, 1, {"--mode", "stall", "--stall-after", "20"});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  const auto t0 = Clock::now();
  for (int i = 0; i < 80; ++i) simulation.period();
  const double elapsed = seconds(t0);
  std::printf("80 periods in %.2f s; missed %llu\n", elapsed,
              (unsigned long long)server.stats(0).missed);
  EXPECT_GE(server.stats(0).missed, 55u);
  EXPECT_LT(elapsed, 60 * 0.05 * 1.5 + 2.0);  // each miss costs the timeout, no more
  EXPECT_TRUE(w.isStanding(0));               // it keeps its last command
}

TEST(Net, TeamMessagesReachTeammatesOnly) {
  const uint32_t domain = 108;
  world::World w(teams(3));  // team 0: numbers 1, 2; team 1: number 1
  net::ServerConfig cfg = serverConfig(domain);
  cfg.lockstep = false;
  cfg.team_message_delay = 0.05;
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  agents::AgentClient a(dds(domain), 0, 1), b(dds(domain), 0, 2), c(dds(domain), 1, 1);
  bool ok_a = false, ok_b = false, ok_c = false;
  std::thread ta([&] { ok_a = a.claim(10.0); }), tb([&] { ok_b = b.claim(10.0); }),
      tc([&] { ok_c = c.claim(10.0); });
  server.waitForOwners(3, 15.0);
  ta.join();
  tb.join();
  tc.join();
  ASSERT_TRUE(ok_a && ok_b && ok_c);
  const std::vector<uint8_t> hello = {'h', 'i', 0, 255};
  a.sendTeamMessage(hello);
  server.poll(0.2);
  std::vector<agents::TeamMessageIn> got_b, got_c;
  // At least 40 periods; more while the message is on its way on a busy machine.
  auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  for (int i = 0; i < 40 || (got_b.empty() && std::chrono::steady_clock::now() < until); ++i) {
    simulation.period();
    dds_sleepfor(DDS_MSECS(2));
    for (auto& m : b.receiveTeamMessages()) got_b.push_back(m);
    for (auto& m : c.receiveTeamMessages()) got_c.push_back(m);
  }
  ASSERT_EQ(got_b.size(), 1u);
  EXPECT_EQ(got_b[0].from_player, 1);
  EXPECT_EQ(got_b[0].data, hello);
  EXPECT_TRUE(got_c.empty());  // the other team hears nothing

  // A message carries the tick of the frame its sender last received, and
  // arrives 0.05 s (5 periods) of simulated time after that tick, whenever
  // it reached the simulator.
  simsoccer_msg_SensorFrame frame{};
  ASSERT_TRUE(b.receive(frame, 2.0));
  while (b.receive(frame, 0.05)) {
  }
  b.sendTeamMessage(hello);
  std::vector<std::pair<uint64_t, agents::TeamMessageIn>> got_a;  // (simulator tick, message)
  until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  for (int i = 0; i < 20 || (got_a.empty() && std::chrono::steady_clock::now() < until); ++i) {
    const uint64_t now = w.controlTick();
    simulation.period();
    dds_sleepfor(DDS_MSECS(2));
    for (auto& m : a.receiveTeamMessages()) got_a.emplace_back(now, m);
  }
  ASSERT_EQ(got_a.size(), 1u);
  EXPECT_EQ(got_a[0].second.from_player, 2);
  EXPECT_EQ(got_a[0].second.tick, frame.tick);
  EXPECT_GE(got_a[0].first, frame.tick + 5);  // relayed in the period of tick sent + 5
                                              // (seen here then, or a little later)
}

TEST(NetApps, BenchNetWritesItsTable) {
  const test::BenchRun run =
      test::runBench(SIMSOCCER_BIN, "bench net --robots 1,2 --seconds 1 --domain 109");
  const std::string& out = run.out;
  ASSERT_EQ(run.status, 0) << out;
  const std::vector<std::string>& lines = run.lines;
  ASSERT_GE(lines.size(), 3u);
  const std::string &header = lines[0], &row1 = lines[1], &row2 = lines[2];
  EXPECT_EQ(header.rfind("robots,overhead_ms_per_period", 0), 0u) << header;
  EXPECT_NE(header.find("bytes_per_tick"), std::string::npos);
  EXPECT_EQ(row1.rfind("1,", 0), 0u);
  EXPECT_EQ(row2.rfind("2,", 0), 0u);
  // The CPU the processes spent on messaging, and the packets: at least a
  // frame and a command per robot and tick.
  const auto cells = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');) out.push_back(cell);
    return out;
  };
  const std::vector<std::string> names = cells(header);
  const auto column = [&](const std::string& row, const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    EXPECT_NE(it, names.end()) << name;
    const std::vector<std::string> values = cells(row);
    const auto k = static_cast<size_t>(it - names.begin());
    if (it == names.end() || k >= values.size() || values[k] == "n/a") {
      ADD_FAILURE() << name << " missing in: " << row;
      return -1.0;
    }
    return std::stod(values[k]);
  };
  EXPECT_GT(column(row1, "net_cpu_ms_per_period"), 0.0);
  EXPECT_GE(column(row1, "packets_per_tick"), 2.0);
  EXPECT_GE(column(row2, "packets_per_tick"), 4.0);
}

// Bad DDS settings are refused with the setting named: a lease out of range,
// a configuration file that is not there (the library and the agent program).
TEST(NetApps, BadLeaseAndMissingDdsConfigAreNamed) {
  net::DomainConfig bad = dds(123);
  bad.lease = 0.01;
  try {
    net::Participant p(bad);
    ADD_FAILURE() << "a 10 ms lease was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lease"), std::string::npos) << e.what();
  }
  net::DomainConfig missing = dds(123);
  missing.config_file = "/nonexistent/loopback.xml";
  try {
    net::Participant p(missing);
    ADD_FAILURE() << "a missing configuration file was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/loopback.xml"), std::string::npos)
        << e.what();
  }
  expectAgentUsageError("--domain 123 --lease 0", "--lease");
}

// simsoccer-agent for a robot another agent owns: --if-owned refuse gives up
// (exit status 3) when the simulator refuses it, long before its claim
// timeout; the default waits the claim timeout out for a release first. The
// owner keeps its robot throughout.
TEST(NetApps, AnAgentProgramRefusedItsRobotGivesUpOrWaits) {
  const uint32_t domain = 124;
  world::World w(teams(1));
  sim::Simulation simulation(w);
  net::SimServer server(simulation, serverConfig(domain, 2.0));
  AgentProcess owner(domain, 0, 1);
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  // Runs the lockstep loop until `agent` exits (at most 25 s): its exit
  // status and the seconds it ran.
  const auto runUntilExit = [&](AgentProcess& agent) {
    const auto t0 = Clock::now();
    int status = -1;
    while (status < 0 && seconds(t0) < 25.0) {
      simulation.period();
      status = agent.exitStatus(0.0);
    }
    return std::make_pair(status, seconds(t0));
  };
  const uint64_t accepted = server.stats(0).accepted;
  AgentProcess refusing(domain, 0, 1, {"--if-owned", "refuse", "--claim-timeout", "20"});
  const auto [refused_status, refused_after] = runUntilExit(refusing);
  EXPECT_EQ(refused_status, 3);
  EXPECT_LT(refused_after, 10.0);  // not the 20 s claim timeout
  AgentProcess waiting(domain, 0, 1, {"--claim-timeout", "2"});
  const auto [waited_status, waited_after] = runUntilExit(waiting);
  EXPECT_EQ(waited_status, 3);
  EXPECT_GT(waited_after, 1.9);  // it waited for a release
  std::printf("refused agent gave up after %.2f s; the waiting one after %.2f s\n", refused_after,
              waited_after);
  EXPECT_TRUE(server.stats(0).owned);
  EXPECT_EQ(server.stats(0).missed, 0u);
  EXPECT_GT(server.stats(0).accepted, accepted + 50);  // the owner drove it all along
  expectAgentUsageError("--domain 124 --if-owned never", "--if-owned");
}

TEST(NetApps, ServeRunsAScenarioForAnExternalAgent) {
  const uint32_t domain = 110;
  AgentProcess agent(domain, 0, 1);
  int status = -1;
  const std::string out =
      runCommand(std::string(SIMSOCCER_BIN) + " serve " + SIMSOCCER_SOURCE_DIR +
                     "/configs/scenarios/lineup_5v5.yaml --agents 1 --seconds 1 --domain " +
                     std::to_string(domain),
                 status);
  std::printf("%s", out.c_str());
  EXPECT_EQ(status, 0) << out;
  // 100 periods; pipelined (the default), the answer to the last one is never applied.
  EXPECT_NE(out.find("team 0 player 1: owned, accepted 99, rejected 0, refused 0, missed 0"),
            std::string::npos)
      << out;
}

TEST(NetGameState, RefereePacketReachesAgents) {
  const uint32_t domain = 111;
  world::World w(teams(1));
  net::ServerConfig cfg = serverConfig(domain);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  agents::AgentClient agent(dds(domain), 0, 1);
  referee::ControlData d;
  d.state = static_cast<uint8_t>(referee::gc::State::Playing);
  d.kicking_team = 13;
  d.secs_remaining = 321;
  d.teams[0].team_number = 13;
  d.teams[1].team_number = 5;
  d.teams[1].score = 2;
  d.teams[0].players[3] = {2, 40};
  simsoccer_msg_GameState m{};
  net::toMessage(d, 7, m);
  server.setGameState(m);
  simsoccer_msg_GameState got{};
  bool have = false;
  for (int i = 0; i < 200 && !have; ++i) {
    dds_sleepfor(DDS_MSECS(10));
    have = agent.gameState(got) && got.secs_remaining == 321;
  }
  ASSERT_TRUE(have);
  EXPECT_EQ(got.state, 3);
  EXPECT_EQ(got.kicking_team, 13);
  EXPECT_EQ(got.teams[1].score, 2);
  EXPECT_EQ(got.teams[0].players[3].penalty, 2);
  EXPECT_EQ(got.teams[0].players[3].secs_till_unpenalised, 40);
}

// The real program with the referee: its decisions reach agents on the
// GameState topic and robot code as GameController packets over UDP.
// The game over UDP as GameController3 sends it, read by the tests' own
// reader (gc_reader.hpp): every state the operator passes through, four
// different team colours, the message budget.
TEST(NetApps, ServeWithTheRefereeBroadcastsTheGame) {
  const uint32_t domain = 112;
  referee::UdpReceiver robot(0, "127.0.0.1");
  agents::AgentClient agent(dds(domain), 0, 1);
  int status = -1;
  std::string out;
  std::atomic<bool> done{false};
  std::thread serve([&] {
    out = runCommand(std::string(SIMSOCCER_BIN) + " serve " + SIMSOCCER_SOURCE_DIR +
                         "/configs/scenarios/lineup_5v5.yaml --agents 0 --seconds 10 --domain " +
                         std::to_string(domain) + " --rules " + SIMSOCCER_SOURCE_DIR +
                         "/configs/rules/spl.yaml --teams 13,5 --gc-address 127.0.0.1 --gc-port " +
                         std::to_string(robot.port()) + " --gc-return-port 0",
                     status);
    done = true;
  });
  std::array<uint8_t, 512> buf{};
  std::vector<test::GcPacket> packets;
  uint8_t dds_state = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < until) {
    const size_t n = robot.receive(buf, 0.5);
    try {
      if (n > 0) packets.push_back(test::readGcPacket(std::span<const uint8_t>(buf.data(), n)));
    } catch (const std::exception& e) {  // counted below: none may come
      ADD_FAILURE() << "not a GameController packet: " << e.what();
    }
    simsoccer_msg_GameState m{};
    if (agent.gameState(m) && m.state == 3) dds_state = 3;
    if (n == 0 && done) break;  // serve is done and nothing is left
  }
  serve.join();
  std::printf("%s", out.c_str());
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("game: PLAYING"), std::string::npos) << out;
  // 10 simulated s at 2 Hz: 20 packets, numbered in order, Initial (1 s) ->
  // Standby (1 s) -> Ready -> Set -> Playing.
  ASSERT_GE(packets.size(), 19u);
  std::vector<int> states;
  for (size_t i = 0; i < packets.size(); ++i) {
    EXPECT_EQ(packets[i].version, 18);
    EXPECT_EQ(packets[i].packet_number, static_cast<int>(i));
    if (states.empty() || states.back() != packets[i].state) states.push_back(packets[i].state);
  }
  EXPECT_EQ(states, (std::vector<int>{0, 5, 1, 2, 3}));  // INITIAL STANDBY READY SET PLAYING
  const test::GcPacket& last = packets.back();
  EXPECT_EQ(last.teams[0].number, 13);
  EXPECT_EQ(last.kicking_team, 13);
  EXPECT_EQ(last.competition_phase, 0);  // round robin
  // GameController3 refuses a colour clash: four different colours.
  const std::set<int> colours = {last.teams[0].field_player_colour, last.teams[0].goalkeeper_colour,
                                 last.teams[1].field_player_colour,
                                 last.teams[1].goalkeeper_colour};
  EXPECT_EQ(colours.size(), 4u);
  EXPECT_EQ(last.teams[0].message_budget, 1200);  // no agents, no messages
  EXPECT_EQ(dds_state, 3);                        // the agent saw Playing on the GameState topic
}

TEST(NetCameras, ImagesReachASubscriberAtTheCameraRates) {
  const uint32_t domain = 113;
  world::Scenario s = teams(1);
  s.cameras.enabled = true;  // as a scenario's `cameras:` block turns them on
  s.cameras.top = {true, 64, 48, 30.0};
  s.cameras.bottom = {true, 32, 24, 10.0};
  world::World w(s);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, serverConfig(domain, 2.0));
  AgentProcess owner(domain, 0, 1);               // drives the robot in lockstep
  agents::AgentClient viewer(dds(domain), 0, 1);  // any participant may watch a robot's cameras
  viewer.subscribeImages();
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  server.poll(0.5);  // the viewer's reader matches the image writer
  const uint64_t first = w.controlTick();
  const int periods = 100;
  size_t got[2] = {0, 0};
  std::vector<agents::CameraImageIn> images;
  auto take = [&](double timeout) {
    for (auto& image : viewer.receiveImages(timeout)) {
      if (image.tick <= first) continue;  // published before the measured interval
      ++got[image.camera];
      images.push_back(std::move(image));
    }
  };
  for (int i = 0; i < periods; ++i) {
    simulation.period();
    take(0.0);  // as an agent would, every period (the reader keeps the last 4 per camera)
  }
  simulation.flushCameras();
  const uint64_t last = first + periods;  // the capture after the last step
  size_t expected[2] = {0, 0};
  for (uint64_t t = first + 1; t <= last; ++t) {
    expected[0] += world::CameraSystem::due(t, 0.01, 30.0);
    expected[1] += world::CameraSystem::due(t, 0.01, 10.0);
  }
  const auto start = Clock::now();
  while ((got[0] < expected[0] || got[1] < expected[1]) && seconds(start) < 10.0) take(0.2);
  std::printf("top %zu of %zu, bottom %zu of %zu images over %d periods\n", got[0], expected[0],
              got[1], expected[1], periods);
  EXPECT_EQ(got[0], expected[0]);
  EXPECT_EQ(got[1], expected[1]);
  for (const auto& image : images) {
    const int w_px = image.camera == 0 ? 64 : 32, h_px = image.camera == 0 ? 48 : 24;
    EXPECT_EQ(image.encoding, 0);  // YUYV
    EXPECT_EQ(image.width, w_px);
    EXPECT_EQ(image.height, h_px);
    EXPECT_EQ(image.data.size(), static_cast<size_t>(w_px * h_px * 2));
    EXPECT_TRUE(world::CameraSystem::due(image.tick, 0.01, image.camera == 0 ? 30.0 : 10.0));
    EXPECT_NEAR(image.sim_time, 0.01 * static_cast<double>(image.tick), 1e-9);
    // The camera sits on the head, about 0.5 m above the carpet, pose a unit quaternion.
    EXPECT_NEAR(image.position[2], 0.5, 0.1);
    const auto& q = image.orientation;
    EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-5);
    EXPECT_NEAR(image.intrinsics[2], 0.5 * w_px, 1e-4);
  }
  EXPECT_EQ(simulation.cameras()->stats().dropped, 0u);  // lockstep waits, never drops
}

TEST(Net, RealTimeAppliesTheLatestCommandEachPeriod) {
  // Real time: the simulator sleeps between periods; commands that arrive
  // meanwhile must be applied at the next period, not discarded.
  const uint32_t domain = 114;
  world::World w(teams(1));
  net::ServerConfig cfg = serverConfig(domain);
  cfg.lockstep = false;
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  AgentProcess agent(domain, 0, 1);
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  const auto period = std::chrono::milliseconds(10);
  auto due = Clock::now();
  const int periods = 150;
  for (int i = 0; i < periods; ++i) {
    due += period;
    std::this_thread::sleep_until(due);
    simulation.period();
  }
  const auto& st = server.stats(0);
  std::printf("real time: %llu commands applied in %d periods\n", (unsigned long long)st.accepted,
              periods);
  EXPECT_GE(st.accepted, static_cast<uint64_t>(periods * 0.7));
  EXPECT_EQ(st.rejected, 0u);
}

TEST(NetMotion, AnAgentProcessWalksItsRobotOneMetre) {
  // Lockstep over DDS: the simsoccer-agent process runs the walk engine on
  // the sensor frames it receives and answers with joint targets only.
  const uint32_t domain = 115;
  world::Scenario s = teams(1);
  s.robots[0].x = -3.0;
  s.robots[0].y = 0.0;
  world::World w(s);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, serverConfig(domain, 2.0));
  AgentProcess agent(domain, 0, 1, {"--mode", "walk", "--vx", "0.2"});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  const engine::Vec3 start = w.torsoPose(0).translation();
  bool fell = false;
  for (int i = 0; i < 700 && !fell; ++i) {  // 1 s easing in + 6 s walking
    simulation.period();
    fell = !w.isStanding(0);
  }
  const engine::Vec3 d = w.torsoPose(0).translation() - start;
  std::printf("walked %.3f m forward, %.3f m sideways in 7 s; fell %d; missed %llu\n", d.x(), d.y(),
              fell, (unsigned long long)server.stats(0).missed);
  EXPECT_FALSE(fell);
  EXPECT_GT(d.x(), 1.0);
  EXPECT_LT(std::abs(d.y()), 0.15);
  EXPECT_EQ(server.stats(0).missed, 0u);
}

TEST(NetPipelined, TheFramesGoOutWhileTheWorldStepsAndEveryAnswerActsAPeriodLater) {
  // Pipelined lockstep through the run loop: a sender thread writes the frames while the
  // world steps, and the periods run on a CPU of their own with the agents on the others
  // (when a CPU is free: other tests' runs may hold them). Every answer is taken, none
  // missed. (ThreadSanitizer runs this: the sender thread and the command listener.)
  const uint32_t domain = 128;
  world::World w(teams(2));
  sim::SimulationConfig c;
  c.mode = sim::Mode::Pipelined;
  sim::Simulation simulation(w, c);
  net::SimServer server(simulation, serverConfig(domain, 2.0));
  AgentProcess a(domain, 0, 1), b(domain, 1, 1);
  ASSERT_TRUE(server.waitForOwners(2, 20.0));
  std::vector<int> agent_cpus;
  const sim::RunStats run = sim::RunLoop(simulation, sim::Pacing::Lockstep).run(200, [&] {
    if (w.controlTick() == 100) {
      cpu_set_t set;
      CPU_ZERO(&set);
      if (sched_getaffinity(a.pid(), sizeof set, &set) == 0)
        for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
          if (CPU_ISSET(cpu, &set)) agent_cpus.push_back(cpu);
    }
  });
  for (world::RobotId r = 0; r < 2; ++r) {
    EXPECT_EQ(server.stats(r).missed, 0u);
    // The answer to the last tick waits for the next period.
    EXPECT_EQ(simulation.commandStats(r).accepted, 199u);
  }
  if (run.period_cpu >= 0) {
    EXPECT_FALSE(agent_cpus.empty());
    for (const int cpu : agent_cpus) EXPECT_NE(cpu, run.period_cpu);
  }
  std::printf("periods on CPU %d; agent on %zu CPU(s)\n", run.period_cpu, agent_cpus.size());
}

TEST(NetPerception, EveryFrameCarriesTheRobotsPerceptionOfItsPeriod) {
  const uint32_t domain = 116;
  world::Scenario s = teams(2);
  s.robots[0].x = -2.0;
  s.robots[0].y = 1.5;
  s.ball_position = {-1.0, 1.5, -1.0};  // 1 m ahead
  s.perception.enabled = true;          // as a scenario's `perception:` block does
  world::World w(s);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, serverConfig(domain, 2.0));
  AgentProcess owner(domain, 0, 1);
  agents::AgentClient viewer(dds(domain), 0, 1);
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  server.poll(0.5);  // the viewer's reader matches
  int received = 0;
  agents::PerceptionIn p;
  simsoccer_msg_SensorFrame frame{};
  for (int i = 0; i < 50; ++i) {
    simulation.period();
    const uint64_t tick = w.controlTick() - 1;
    const auto start = Clock::now();
    bool got = false;
    while (!got && seconds(start) < 1.0) got = viewer.receive(frame, 0.05) && frame.tick == tick;
    if (got && agents::perceptionFromFrame(frame, p) && p.tick == tick) ++received;
  }
  std::printf("perception in %d of 50 frames; ball at (%.3f, %.3f), in view %d, %zu robots\n",
              received, p.ball.x, p.ball.y, p.ball.in_view, p.robots.size());
  EXPECT_GE(received, 45);
  EXPECT_TRUE(p.ball.in_view);
  EXPECT_NEAR(p.ball.x, 1.0, 0.05);
  EXPECT_NEAR(p.ball.y, 0.0, 0.05);
  EXPECT_NEAR(p.self_pose[0], -2.0, 0.05);
  ASSERT_EQ(p.robots.size(), 1u);  // the other robot, seen or not
  EXPECT_EQ(p.robots[0].kind, 2);
  EXPECT_EQ(p.robots[0].team, 1);
}

TEST(NetPerception, WithPerceptionOffAFrameCarriesNone) {
  const uint32_t domain = 120;
  world::Scenario s = teams(1);
  world::World w(s);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, serverConfig(domain, 2.0));
  agents::AgentClient viewer(dds(domain), 0, 1);
  server.poll(0.5);  // the viewer's reader matches
  simsoccer_msg_SensorFrame frame{};
  bool got = false;
  for (int i = 0; i < 20 && !got; ++i) {
    simulation.period();
    got = viewer.receive(frame, 0.2);
  }
  ASSERT_TRUE(got);
  agents::PerceptionIn p;
  EXPECT_FALSE(agents::perceptionFromFrame(frame, p));
  EXPECT_EQ(frame.perception.robots._length, 0u);
}

TEST(NetKick, AStrikerAgentKicksTheBallTwoMetres) {
  // Lockstep over DDS: simsoccer-agent --role striker sees the ball through
  // its Perception, lines up behind it and kicks (joint targets only).
  const uint32_t domain = 117;
  world::Scenario s = teams(1);
  s.robots[0].x = 0.0;
  s.robots[0].y = 0.0;
  s.ball_position = {0.4, 0.05, -1.0};  // ahead, towards the +x goal
  s.perception.enabled = true;
  world::World w(s);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, serverConfig(domain, 2.0));
  AgentProcess agent(domain, 0, 1, {"--role", "striker"});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  const engine::Vec3 start = w.ballState().pose.translation();
  double travelled = 0.0;
  bool fell = false;
  for (int i = 0; i < 2500 && travelled < 2.0; ++i) {  // up to 25 s
    simulation.period();
    fell = fell || !w.isStanding(0);
    travelled = (w.ballState().pose.translation() - start).head<2>().norm();
  }
  // Let the ball roll out.
  for (int i = 0; i < 400; ++i) simulation.period();
  travelled = (w.ballState().pose.translation() - start).head<2>().norm();
  const engine::Vec3 d = w.ballState().pose.translation() - start;
  std::printf("ball travelled %.2f m (%.2f, %.2f); robot fell %d\n", travelled, d.x(), d.y(), fell);
  EXPECT_GE(travelled, 2.0);
  EXPECT_GT(d.x(), 1.5);  // towards the goal it attacks
  EXPECT_FALSE(fell);
}

TEST(NetGetUp, AnAgentProcessGetsItsRobotUpFromItsBack) {
  // Lockstep over DDS: the robot starts lying on its back; simsoccer-agent
  // (get-up on by default) detects it from the IMU, rolls onto its front and gets up
  // (joint targets only), within the 8 s the motion figures ask for.
  const uint32_t domain = 118;
  world::Scenario s = teams(1);
  s.perception.enabled = true;
  world::World w(s);
  engine::Pose torso = engine::Pose::Identity();
  torso.linear() = Eigen::AngleAxisd(-M_PI / 2, engine::Vec3::UnitY()).toRotationMatrix();
  torso.translation() = engine::Vec3(-2.0, 1.0, 0.16);
  w.placeRobot(0, torso, "stand");
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();  // settled on its back
  ASSERT_GT(w.torsoPose(0).linear()(2, 0), 0.9);        // chest up
  net::ServerConfig config = serverConfig(domain, 2.0);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, config);
  AgentProcess agent(domain, 0, 1, {"--role", "defender"});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  double standing_for = 0.0, up_at = -1.0;
  const double dt = s.physics.control_period;
  for (int i = 0; i < 1000 && standing_for < 1.0; ++i) {  // up to 10 s
    simulation.period();
    standing_for = w.isStanding(0) ? standing_for + dt : 0.0;
    if (standing_for >= 1.0) up_at = (i + 1) * dt - 1.0;
  }
  std::printf("standing from %.2f s (-1: never); missed %llu\n", up_at,
              (unsigned long long)server.stats(0).missed);
  EXPECT_GE(up_at, 0.0);
  EXPECT_LT(up_at, 8.0);
  EXPECT_EQ(server.stats(0).missed, 0u);
}

TEST(NetSit, AnAgentProcessSitsDownWhenTheGameIsOverAndStandsUpForTheNext) {
  // Lockstep over DDS: a soccer agent process reads Finished from the
  // GameState and sits down on its feet (still standing to the referee),
  // resting on soft joints; Initial (the next half) stands it up again.
  const uint32_t domain = 119;
  world::World w(teams(1));
  net::ServerConfig config = serverConfig(domain, 2.0);
  sim::Simulation simulation(w);
  net::SimServer server(simulation, config);
  referee::ControlData d;
  d.state = static_cast<uint8_t>(referee::gc::State::Finished);
  d.teams[0].team_number = 1;
  d.teams[1].team_number = 2;
  simsoccer_msg_GameState m{};
  net::toMessage(d, 0, m);
  server.setGameState(m);
  AgentProcess agent(domain, 0, 1, {"--role", "defender", "--game-state-wait", "10"});
  ASSERT_TRUE(server.waitForOwners(1, 20.0));
  const double standing = w.torsoPose(0).translation().z();
  double lowest = 1.0;
  for (int i = 0; i < 400; ++i) {  // 4 s: down in 1.5 s, then resting
    simulation.period();
    lowest = std::min(lowest, w.torsoPose(0).translation().z());
    ASSERT_TRUE(w.isStanding(0)) << i;
  }
  const double sitting = w.torsoPose(0).translation().z();
  const float leg_stiffness = w.sensorFrame(0).stiffness[10];  // a knee (actuator order)
  std::printf("torso standing %.3f m, sitting %.3f m, knee stiffness %.2f\n", standing, sitting,
              leg_stiffness);
  EXPECT_LT(sitting, standing - 0.05);
  EXPECT_GT(lowest, 0.22);
  EXPECT_LT(leg_stiffness, 0.5f);
  d.state = static_cast<uint8_t>(referee::gc::State::Initial);
  net::toMessage(d, 400, m);
  server.setGameState(m);
  for (int i = 0; i < 400; ++i) {  // up again within 4 s
    simulation.period();
    ASSERT_TRUE(w.isStanding(0)) << i;
  }
  EXPECT_NEAR(w.torsoPose(0).translation().z(), standing, 0.02);
  EXPECT_GT(w.sensorFrame(0).stiffness[10], 0.9f);
  EXPECT_EQ(server.stats(0).missed, 0u);
}

// The agent program is built from the agent side alone: the protocol, the DDS
// layer, the robot and field descriptions and the agents library; no physics,
// renderer, world or referee (checked on the built binary, as `ldd` and `nm`
// show it).
TEST(NetApps, TheAgentProgramLinksNoPhysicsRendererWorldOrReferee) {
  int status = -1;
  const std::string libraries =
      runCommand(std::string("ldd ") + SIMSOCCER_AGENT_BIN + " 2>&1", status);
  ASSERT_EQ(status, 0) << libraries;
  ASSERT_NE(libraries.find("libddsc"), std::string::npos) << libraries;  // it does speak DDS
  for (const char* lib : {"Bullet", "opencv", "libEGL", "libGL", "libOpenGL"})
    EXPECT_EQ(libraries.find(lib), std::string::npos) << lib << " in\n" << libraries;
  const std::string symbols =
      runCommand(std::string("nm -C ") + SIMSOCCER_AGENT_BIN + " 2>&1", status);
  ASSERT_EQ(status, 0);
  ASSERT_NE(symbols.find("simsoccer::agents::"), std::string::npos);
  for (const char* part : {"simsoccer::world::", "simsoccer::referee::", "simsoccer::sim::",
                           "simsoccer::engine::PhysicsWorld"})
    EXPECT_EQ(symbols.find(part), std::string::npos) << part;
}

// One simulator per DDS domain on a host (net/domain_claim.hpp): a second
// claim of a held domain is refused, naming the holder; the Booster SDK's
// topics are claimed apart; the claim goes with its holder.
TEST(DomainClaim, ADomainIsClaimedOncePerHostAndFreedWithItsHolder) {
  {
    net::DomainClaim held = net::DomainClaim::claim(231);
    EXPECT_EQ(held.domain(), 231u);
    try {
      (void)net::DomainClaim::claim(231);
      ADD_FAILURE() << "a held domain was claimed again";
    } catch (const net::DomainInUse& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("DDS domain 231 is in use on this host"), std::string::npos) << what;
      EXPECT_NE(what.find("pid " + std::to_string(::getpid())), std::string::npos) << what;
      EXPECT_NE(what.find("--domain"), std::string::npos) << what;
    }
    // The Booster SDK's topics share no name with simsoccer's.
    const net::DomainClaim booster = net::DomainClaim::claim(231, net::DomainTopics::Booster);
    EXPECT_THROW((void)net::DomainClaim::claim(231, net::DomainTopics::Booster), net::DomainInUse);
    // Moved, it is still held.
    const net::DomainClaim moved = std::move(held);
    EXPECT_THROW((void)net::DomainClaim::claim(231), net::DomainInUse);
  }
  EXPECT_EQ(net::DomainClaim::claim(231).domain(), 231u);
}

TEST(DomainClaim, FirstFreeSkipsHeldDomains) {
  const net::DomainClaim a = net::DomainClaim::claim(229);
  const net::DomainClaim b = net::DomainClaim::firstFree(229, 230);
  EXPECT_EQ(b.domain(), 230u);
  EXPECT_THROW((void)net::DomainClaim::firstFree(229, 230), net::DomainInUse);
}

// The programs refuse a held --domain before anything runs, naming it and its
// holder.
TEST(NetApps, TheProgramsRefuseAHeldDomain) {
  const net::DomainClaim held = net::DomainClaim::claim(232);
  const std::string scenario =
      (test::sourceDir() / "configs" / "scenarios" / "lineup_5v5.yaml").string();
  int status = -1;
  const std::string out = test::runCommand(
      std::string(SIMSOCCER_BIN) + " serve " + scenario + " --domain 232 --seconds 1", status);
  EXPECT_EQ(WEXITSTATUS(status), 1) << out;
  EXPECT_NE(out.find("simsoccer's DDS domain 232 is in use on this host by pid " +
                     std::to_string(::getpid())),
            std::string::npos)
      << out;
  const std::string bench = test::runCommand(
      std::string(SIMSOCCER_BIN) + " bench net --robots 1 --seconds 0.2 --domain 232", status);
  EXPECT_EQ(WEXITSTATUS(status), 1) << bench;
  EXPECT_NE(bench.find("DDS domain 232 is in use"), std::string::npos) << bench;
}
