// The Booster SDK endpoint with a client written for the tests in a separate
// process (tests/booster_test_client.cpp), on real DDS over loopback: a
// simulated K1 on its own domain, its modes by RPC, CUSTOM-mode joint
// commands with their own gains in lockstep, bad commands refused.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <thread>

#include "booster_sdk.h"
#include "child_process.hpp"
#include "simsoccer/booster/endpoint.hpp"
#include "simsoccer/lola/field_network.hpp"
#include "simsoccer/net/dds.hpp"
#include "simsoccer/referee/gamecontroller_link.hpp"
#include "simsoccer/sim/officials.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using nlohmann::json;

namespace {

// A test client as a process, its standard output (one JSON line) in a file.
struct ClientProcess {
  std::filesystem::path out;
  test::ChildProcess process;
  // `environment`: NAME=VALUE entries added to this process's.
  explicit ClientProcess(std::vector<std::string> args, std::vector<std::string> environment = {})
      : out(std::filesystem::temp_directory_path() /
            ("simsoccer_booster_client_" + std::to_string(getpid()) + ".json")),
        process(std::move(args), std::move(environment), out) {}
  ~ClientProcess() {
    process.kill();
    std::filesystem::remove(out);
  }
  json result() const {
    std::ifstream f(out);
    std::string line;
    std::getline(f, line);
    return line.empty() ? json() : json::parse(line);
  }
};

// A participant's configuration on `domain` with the project's loopback DDS.
net::DomainConfig loopback(uint32_t domain) {
  net::DomainConfig c;
  c.domain = domain;
  c.config_file = test::sourceDir() / "configs/dds/loopback.xml";
  return c;
}

booster::BoosterRobot served(world::RobotId robot, uint32_t domain) {
  booster::BoosterRobot b;
  b.robot = robot;
  b.domain = domain;
  return b;
}

world::Scenario k1Scenario() {
  world::Scenario s = test::scenario(1);
  s.robot_model_file = test::boosterK1();
  return s;
}

// One K1 served to SDK clients: its world, the simulation (lockstep or not)
// and the endpoint, with the project's loopback DDS configuration.
struct ServedK1 {
  world::World w;
  sim::Simulation simulation;
  booster::Endpoint endpoint;
  ServedK1(const booster::BoosterRobot& robot, bool lockstep,
           const world::Scenario& scenario = k1Scenario(), sim::Mode mode = sim::Mode::Serial)
      : w(scenario),
        simulation(w,
                   [&] {
                     sim::SimulationConfig c;
                     c.lockstep = lockstep;
                     c.mode = mode;
                     return c;
                   }()),
        endpoint(w, [&] {
          booster::EndpointConfig c;
          c.robots = {robot};
          c.dds_config = test::sourceDir() / "configs/dds/loopback.xml";
          c.lockstep = lockstep;
          return c;
        }()) {
    simulation.addSource(endpoint);
  }
};

// Runs periods until the client process ends (60 s at most); until the
// client commands (CUSTOM) nothing waits, so the loop paces itself at about
// twice real time (always, with `pace`: a client that walks the robot through
// the locomotion API commands no joints, and unpaced the walk would last as
// many simulated seconds as the machine is fast). Returns the client's exit status.
int runUntilTheClientEnds(sim::Simulation& simulation, const booster::Endpoint& endpoint,
                          ClientProcess& client, bool pace = false, int pace_ms = 5) {
  int status = -1;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while ((status = client.process.exitStatus(0)) < 0 && std::chrono::steady_clock::now() < end) {
    simulation.period();
    if (pace || endpoint.stats(0).applied == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(pace_ms));
  }
  return status;
}

// The test client on robot 0's domain with the project's loopback DDS configuration and
// `args`, paced (`pace_ms` per period) until it ends; its one-line result, its exit status
// in `status`.
json runPacedClient(ServedK1& k1, std::vector<std::string> args, int& status, int pace_ms = 5) {
  args.insert(args.begin(), {SIMSOCCER_BOOSTER_CLIENT, "--domain",
                             std::to_string(k1.endpoint.config().robots[0].domain), "--dds-config",
                             (test::sourceDir() / "configs/dds/loopback.xml").string()});
  ClientProcess client(std::move(args));
  if (!client.process.started()) {
    status = -1;
    return json();
  }
  status = runUntilTheClientEnds(k1.simulation, k1.endpoint, client, /*pace=*/true, pace_ms);
  const json r = client.result();
  std::printf("client: %s\n", r.dump().c_str());
  return r;
}

}  // namespace

TEST(BoosterEndpoint, AnSdkClientDrivesAK1InCustomMode) {
  ServedK1 k1(served(0, 170), /*lockstep=*/true);
  auto& [w, simulation, endpoint] = k1;

  const int periods = 300;
  ClientProcess client({SIMSOCCER_BOOSTER_CLIENT, "--domain", "170", "--dds-config",
                        (test::sourceDir() / "configs/dds/loopback.xml").string(), "--periods",
                        std::to_string(periods)});
  ASSERT_TRUE(client.process.started());
  const int status = runUntilTheClientEnds(simulation, endpoint, client);
  const json r = client.result();
  std::printf("client: %s\n", r.dump().c_str());
  ASSERT_EQ(status, 0) << r.dump();
  EXPECT_EQ(r.at("motors"), 22);    // JointIndexK1
  EXPECT_EQ(r.at("parallel"), 22);  // motor space: the same joints until the linkage is modelled
  EXPECT_NEAR(r.at("acc_z").get<double>(), 9.81, 0.5);
  EXPECT_NEAR(r.at("head_yaw").get<double>(), 0.4, 0.03);

  const auto s = endpoint.stats(0);
  std::printf("states %llu, commands %llu, applied %llu, refused %llu, missed %llu\n",
              (unsigned long long)s.states_sent, (unsigned long long)s.commands,
              (unsigned long long)s.applied, (unsigned long long)s.refused,
              (unsigned long long)s.missed);
  EXPECT_EQ(s.mode, booster::RobotMode::Custom);
  EXPECT_EQ(s.commands, static_cast<uint64_t>(periods + 2));  // one per period, two bad extra
  EXPECT_EQ(s.refused, 3u);  // 21 entries, PARALLEL, the NaN (the gate)
  // Every good command drives the robot, but two that arrive in one period
  // drive it once (the later): 299 good ones, nearly one per period.
  EXPECT_LE(s.applied, static_cast<uint64_t>(periods - 1));
  EXPECT_GE(s.applied, static_cast<uint64_t>(periods - 4));
  // After its last command the client asks GetMode and exits: the periods
  // until the test sees it gone wait in vain (at most two).
  EXPECT_LE(s.missed, 2u);
  EXPECT_EQ(s.requests, 7u);
  EXPECT_EQ(s.requests_refused, 2u);    // walking, Move
  EXPECT_EQ(s.requests_malformed, 2u);  // mode 9, the garbage header
  // The world did what the commands said: head turned, robot standing.
  const int head = w.robot(0).model->body->jointIndex("HeadYaw");
  EXPECT_NEAR(w.physics().jointPosition(w.robot(0).body, head), 0.4, 0.03);
  EXPECT_TRUE(w.isStanding(0));
}

// Team code that uses Booster's walk: WALKING mode and Move, answered by simsoccer's own K1
// walk (configs/motions/booster_k1); the robot walks forward, its head turned as asked, then
// CUSTOM for a second, then walks on.
TEST(BoosterEndpoint, MoveWalksTheK1WithSimsoccersWalk) {
  booster::BoosterRobot robot = served(0, 174);
  robot.motions = test::sourceDir() / "configs/motions/booster_k1";
  ServedK1 k1(robot, /*lockstep=*/false);
  auto& [w, simulation, endpoint] = k1;
  const engine::Vec3 start = w.torsoPose(0).translation();
  int status = -1;
  const json r =
      runPacedClient(k1, {"--periods", "400", "--walk", "0.3", "--custom-between", "100"}, status);
  ASSERT_EQ(status, 0) << r.dump();
  const engine::Pose torso = w.torsoPose(0);
  const engine::Vec3 moved = torso.translation() - start;
  const auto s = endpoint.stats(0);
  std::printf(
      "walked %.2f m forward, %.2f m sideways in %.1f s; requests %llu, walk starts %llu, "
      "custom commands applied %llu\n",
      moved.x(), moved.y(), w.time(), (unsigned long long)s.requests,
      (unsigned long long)s.walk_starts, (unsigned long long)s.applied);
  EXPECT_EQ(s.mode, booster::RobotMode::Walking);
  EXPECT_EQ(s.requests_refused, 0u);
  EXPECT_EQ(s.requests_malformed, 0u);
  // Twice 4 s of LowStates at 0.3 m/s, the walk's speed ramp and the stops included, and
  // CUSTOM in between; the walk starts over on its second entry (from the joints as CUSTOM
  // left them, not where its steps had stopped).
  EXPECT_EQ(s.walk_starts, 2u);
  EXPECT_EQ(s.refused, 0u);
  EXPECT_GT(s.applied, 50u);
  EXPECT_GT(moved.x(), 1.5);
  EXPECT_LT(std::abs(moved.y()), 0.3);
  EXPECT_TRUE(w.isStanding(0));
  const int head = w.robot(0).model->body->jointIndex("HeadYaw");
  EXPECT_NEAR(w.physics().jointPosition(w.robot(0).body, head), 0.3, 0.05);
}

// rt/fall_down as a client watching its K1 in WALKING mode sees a fall: on its front, the robot
// is reported fallen, then getting up (the walk's own recovery), then ready again, with
// recovery available throughout (the robot gets up by itself in WALKING and SOCCER).
TEST(BoosterEndpoint, FallDownReportsTheFallAndTheGetUp) {
  booster::BoosterRobot robot = served(0, 187);
  robot.motions = test::sourceDir() / "configs/motions/booster_k1";
  robot.initial_mode = booster::RobotMode::Walking;
  ServedK1 k1(robot, /*lockstep=*/false);
  auto& [w, simulation, endpoint] = k1;
  net::Participant participant(loopback(187));
  net::QosSpec q;
  q.reliable = true;
  q.depth = 64;
  net::Reader<booster_interface_msg_dds__FallDownState_> fall(
      participant, booster_interface_msg_dds__FallDownState__desc, "rt/fall_down", q);
  std::vector<int> states;  // each change, in order
  bool recovery = true;
  const auto look = [&] {
    fall.take([&](const booster_interface_msg_dds__FallDownState_& m, const dds_sample_info_t& i) {
      if (!i.valid_data) return;
      recovery = recovery && m.is_recovery_available;
      if (states.empty() || states.back() != static_cast<int>(m.fall_down_state))
        states.push_back(static_cast<int>(m.fall_down_state));
    });
  };
  for (int i = 0; i < 100; ++i) {  // standing in WALKING mode; the reader matched meanwhile
    simulation.period();
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    look();
  }
  engine::Pose lying = engine::Pose::Identity();
  lying.linear() = Eigen::AngleAxisd(M_PI / 2, engine::Vec3::UnitY()).toRotationMatrix();
  lying.translation() = engine::Vec3(-2.0, 0.0, 0.2);
  w.placeRobot(0, lying, "stand");
  for (int i = 0;
       i < 2000 && !(states.size() > 2 && states.back() == booster_interface_msg_dds__IS_READY);
       ++i) {
    simulation.period();
    if (i % 10 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    look();
  }
  std::string seen;
  for (int s : states) seen += std::to_string(s) + " ";
  std::printf("rt/fall_down states: %s(0 ready, 1 falling, 2 fallen, 3 getting up)\n",
              seen.c_str());
  const auto at = [&](int s) { return std::find(states.begin(), states.end(), s); };
  ASSERT_FALSE(states.empty());
  EXPECT_EQ(states.front(), booster_interface_msg_dds__IS_READY) << seen;
  EXPECT_NE(at(booster_interface_msg_dds__HAS_FALLEN), states.end()) << seen;
  EXPECT_NE(at(booster_interface_msg_dds__IS_GETTING_UP), states.end()) << seen;
  EXPECT_LT(at(booster_interface_msg_dds__HAS_FALLEN), at(booster_interface_msg_dds__IS_GETTING_UP))
      << seen;
  EXPECT_EQ(states.back(), booster_interface_msg_dds__IS_READY) << seen;
  EXPECT_TRUE(recovery);
  EXPECT_TRUE(w.isStanding(0));
}

// What Booster's soccer demo (and the teams built on it) reads besides the low state: the
// odometry of the walk (rt/odometer_state: x, y, theta since the start or the last
// ResetOdometry) and the head in the robot's base frame (rt/head_pose, geometry_msgs/Pose:
// the demo intersects camera rays with its z = 0 plane), both with ROS 2's default QoS
// (reliable, depth 1 in the demo) as they would subscribe.
TEST(BoosterEndpoint, OdometryAndTheHeadPoseGoOutAsBoostersDemoReadsThem) {
  booster::BoosterRobot robot = served(0, 186);
  robot.motions = test::sourceDir() / "configs/motions/booster_k1";
  ServedK1 k1(robot, /*lockstep=*/false);
  auto& [w, simulation, endpoint] = k1;
  net::Participant participant(loopback(186));
  net::QosSpec q;
  q.reliable = true;
  q.depth = 1;
  net::Reader<booster_interface_msg_dds__Odometer_> odometer(
      participant, booster_interface_msg_dds__Odometer__desc, "rt/odometer_state", q);
  net::Reader<geometry_msgs_msg_dds__Pose_> head_pose(
      participant, geometry_msgs_msg_dds__Pose__desc, "rt/head_pose", q);
  net::Writer<booster_msgs_msg_dds__RpcReqMsg_> requests(
      participant, booster_msgs_msg_dds__RpcReqMsg__desc, "rt/LocoApiTopicReq", [] {
        net::QosSpec r;
        r.reliable = true;
        r.depth = 10;
        return r;
      }());
  const engine::Pose start = w.torsoPose(0);
  int status = -1;
  runPacedClient(k1, {"--periods", "300", "--walk", "0.3"}, status);
  ASSERT_EQ(status, 0);
  const auto latest = [&](auto& reader, auto& out) {
    bool got = false;
    for (int i = 0; i < 100 && !got; ++i) {
      simulation.period();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      reader.take([&](const auto& m, const dds_sample_info_t& info) {
        if (info.valid_data) {
          out = m;
          got = true;
        }
      });
    }
    return got;
  };
  booster_interface_msg_dds__Odometer_ odo{};
  ASSERT_TRUE(latest(odometer, odo)) << "no rt/odometer_state";
  // The trunk's planar pose since the start, in the start's heading.
  const engine::Pose now = w.torsoPose(0);
  const double start_yaw = std::atan2(start.linear()(1, 0), start.linear()(0, 0));
  const double yaw = std::atan2(now.linear()(1, 0), now.linear()(0, 0));
  const engine::Vec3 moved = now.translation() - start.translation();
  const double c = std::cos(start_yaw), s = std::sin(start_yaw);
  std::printf("odometer %.3f %.3f %.3f; the trunk moved %.3f %.3f, turned %.3f\n", odo.x, odo.y,
              odo.theta, c * moved.x() + s * moved.y(), -s * moved.x() + c * moved.y(),
              yaw - start_yaw);
  EXPECT_GT(odo.x, 0.5);
  EXPECT_NEAR(odo.x, c * moved.x() + s * moved.y(), 0.02);
  EXPECT_NEAR(odo.y, -s * moved.x() + c * moved.y(), 0.02);
  EXPECT_NEAR(odo.theta, std::remainder(yaw - start_yaw, 2 * std::numbers::pi), 0.02);
  // The head (the client turned it to yaw 0.3): about 0.9 m up, turned 0.3 from the trunk.
  geometry_msgs_msg_dds__Pose_ head{};
  ASSERT_TRUE(latest(head_pose, head)) << "no rt/head_pose";
  const Eigen::Quaterniond hq(head.orientation.w, head.orientation.x, head.orientation.y,
                              head.orientation.z);
  const Eigen::Vector3d forward = hq * Eigen::Vector3d::UnitX();
  std::printf("head at %.3f %.3f %.3f, looking along %.2f %.2f %.2f\n", head.position.x,
              head.position.y, head.position.z, forward.x(), forward.y(), forward.z());
  EXPECT_NEAR(hq.norm(), 1.0, 1e-6);
  EXPECT_GT(head.position.z, 0.6);
  EXPECT_LT(head.position.z, 1.1);
  EXPECT_LT(std::abs(head.position.x), 0.15);
  EXPECT_NEAR(std::atan2(forward.y(), forward.x()), 0.3, 0.08);
  // ResetOdometry (2031): the origin moves to where the robot stands.
  const std::string header = R"({"api_id": 2031, "expect_response": true})";
  booster_msgs_msg_dds__RpcReqMsg_ reset{};
  reset.uuid = const_cast<char*>("reset-1");
  reset.header = const_cast<char*>(header.c_str());
  reset.body = const_cast<char*>("");
  for (int i = 0; i < 200; ++i) {  // discovery: matched with the robot's request reader
    dds_publication_matched_status_t matched{};
    dds_get_publication_matched_status(requests.get(), &matched);
    if (matched.current_count > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  requests.write(reset);
  booster_interface_msg_dds__Odometer_ after{1e9f, 1e9f, 1e9f};
  for (int i = 0; i < 50 && std::abs(after.x) > 0.05; ++i) latest(odometer, after);
  EXPECT_NEAR(after.x, 0.0, 0.05);
  EXPECT_NEAR(after.y, 0.0, 0.05);
  EXPECT_NEAR(after.theta, 0.0, 0.05);
}

// A K1 on the HSL M-Field (its size 3 ball) at the centre facing +x, with the simulation's
// perception (ideal: what its cameras' frustums hold) for its locomotion service's kicks.
world::Scenario k1KickScenario() {
  world::Scenario s = k1Scenario();
  s.field_file = test::sourceDir() / "fields/hsl_m.yaml";
  s.robots[0].x = 0.0;
  s.robots[0].y = 0.0;
  s.perception.enabled = true;
  return s;
}

// Team code that kicks through Booster's soccer mode (HULKs, NUbots): VisualKick started, its
// direction on rt/kick_ball; simsoccer's K1 walks to the ball its perception sees, lines up
// behind it on that line and kicks it, with the walk's own kick.
TEST(BoosterEndpoint, TheVisualKickGoesToTheBallAndKicksItTheWayAsked) {
  booster::BoosterRobot robot = served(0, 175);
  robot.motions = test::sourceDir() / "configs/motions/booster_k1";
  // Pipelined, as simsoccer serve runs.
  ServedK1 k1(robot, /*lockstep=*/false, k1KickScenario(), sim::kDefaultMode);
  auto& [w, simulation, endpoint] = k1;
  // The ball 1.5 m ahead, to be kicked 0.7 rad to the left of the robot's heading at the start
  // (the field's +x): the K1 walks round to behind it on that line first.
  test::putBallOnCarpet(w, 1.5, 0.0);
  int status = -1;
  const json r =
      runPacedClient(k1, {"--periods", "1100", "--kick", "visual", "--kick-dir", "0.7"}, status);
  ASSERT_EQ(status, 0) << r.dump();
  const engine::Vec3 ball = w.ballState().pose.translation();
  const auto s = endpoint.stats(0);
  std::printf(
      "ball at (%.2f, %.2f) after %.1f s; kicks %llu, targets %llu, falls %llu, get-ups %llu\n",
      ball.x(), ball.y(), w.time(), (unsigned long long)s.kicks, (unsigned long long)s.kick_targets,
      (unsigned long long)s.falls, (unsigned long long)s.get_ups);
  EXPECT_EQ(s.kick_targets, 3u);
  EXPECT_EQ(s.kick_targets_refused, 0u);
  EXPECT_GE(s.kicks, 1u);
  EXPECT_EQ(s.requests_malformed, 1u);  // {"start": "yes"}
  EXPECT_EQ(s.requests_refused, 1u);    // Shoot while the visual kick runs: 502
  // Kicked at least 2 m on, 0.7 rad off +x within the line-up's 0.15 rad and the spread of the
  // K1's kicks after walking (its support foot turns during the kick: 0.1-0.26 rad seen; with
  // the contacts warm-started this kick went 0.34 rad, 0.36 off).
  const double travelled = std::hypot(ball.x() - 1.5, ball.y());
  const double direction = std::atan2(ball.y(), ball.x() - 1.5);
  std::printf("travelled %.2f m at %.2f rad\n", travelled, direction);
  EXPECT_GT(travelled, 2.0);
  EXPECT_NEAR(direction, 0.7, 0.41);
  // The K1 falls after some of its kicks from walking (docs/agents.md): here at most once, after
  // the kick (the walk then gets it up).
  EXPECT_LE(s.falls, 1u);
}

// Shoot: one kick where the robot stands, with the foot on the ball's side. At the K1's 2 ms
// control period (configs/scenarios/k1_3v3.yaml) and serial periods: the walk still runs every
// 10 ms, its targets acting 10 ms later, as the kick was tuned (at 2 ms with 2 ms of delay, or
// serial at 10 ms, the K1 fell after every kick).
TEST(BoosterEndpoint, ShootKicksTheBallInFrontOfTheK1) {
  booster::BoosterRobot robot = served(0, 176);
  robot.motions = test::sourceDir() / "configs/motions/booster_k1";
  world::Scenario scenario = k1KickScenario();
  scenario.physics.dt = scenario.physics.control_period = 0.002;
  ServedK1 k1(robot, /*lockstep=*/false, scenario, sim::Mode::Serial);
  auto& [w, simulation, endpoint] = k1;
  // In front of the left foot, where the walk's kick meets it (configs/motions/booster_k1/
  // kick_approach.yaml: 0.25 m ahead, 0.095 m to the side).
  test::putBallOnCarpet(w, 0.25, 0.095);
  int status = -1;
  const json r =
      runPacedClient(k1, {"--periods", "2500", "--kick", "shoot", "--scale", "5"}, status, 1);
  ASSERT_EQ(status, 0) << r.dump();
  const engine::Vec3 ball = w.ballState().pose.translation();
  const auto s = endpoint.stats(0);
  std::printf("ball at (%.2f, %.2f) after %.1f s; kicks %llu\n", ball.x(), ball.y(), w.time(),
              (unsigned long long)s.kicks);
  EXPECT_EQ(s.kicks, 1u);
  EXPECT_GT(ball.x(), 3.0);
  EXPECT_LT(std::abs(ball.y()), 0.3 * ball.x());
  EXPECT_TRUE(w.isStanding(0));
}

// Two robots cannot share a domain (the SDK's topics carry no robot id), and
// a robot is served once.
TEST(BoosterEndpoint, OneRobotPerDomain) {
  world::Scenario s = k1Scenario();
  s.robots.push_back(s.robots[0]);
  s.robots[1].number = 2;
  s.robots[1].y = 1.0;
  world::World w(s);
  booster::EndpointConfig ec;
  ec.dds_config = test::sourceDir() / "configs/dds/loopback.xml";
  ec.robots = {served(0, 181), served(1, 181)};
  EXPECT_THROW(booster::Endpoint(w, ec), std::invalid_argument);
  ec.robots = {served(0, 181), served(0, 182)};
  EXPECT_THROW(booster::Endpoint(w, ec), std::invalid_argument);
  ec.robots = {served(0, 181), served(1, 182)};
  EXPECT_NO_THROW(booster::Endpoint(w, ec));
}

// The SDK's own middleware: a client on Fast DDS (Debian's 2.9) with the
// SDK's classic-CDR types and names and the participant profile
// "booster_dds" from configs/dds/booster_fastdds.xml, as a team process on
// this machine would use it, against the Cyclone endpoint.
TEST(BoosterEndpoint, AFastDdsClientWithTheShippedProfileDrivesAK1) {
  ServedK1 k1(served(0, 173), /*lockstep=*/true);
  auto& [w, simulation, endpoint] = k1;
  const int periods = 200;
  ClientProcess client(
      {SIMSOCCER_BOOSTER_FASTDDS_CLIENT, "--domain", "173", "--periods", std::to_string(periods)},
      {"FASTRTPS_DEFAULT_PROFILES_FILE=" +
       (test::sourceDir() / "configs/dds/booster_fastdds.xml").string()});
  ASSERT_TRUE(client.process.started());
  const int status = runUntilTheClientEnds(simulation, endpoint, client);
  const json r = client.result();
  std::printf("Fast DDS client: %s\n", r.dump().c_str());
  ASSERT_EQ(status, 0) << r.dump();
  EXPECT_EQ(r.at("motors"), 22);
  EXPECT_NEAR(r.at("head_yaw").get<double>(), 0.4, 0.03);
  EXPECT_NEAR(r.at("acc_z").get<double>(), 9.81, 1.0);
  const auto s = endpoint.stats(0);
  EXPECT_EQ(s.mode, booster::RobotMode::Custom);
  EXPECT_EQ(s.refused, 0u);
  EXPECT_GE(s.applied, static_cast<uint64_t>(periods - 3));
  const int head = w.robot(0).model->body->jointIndex("HeadYaw");
  EXPECT_NEAR(w.physics().jointPosition(w.robot(0).body, head), 0.4, 0.03);
  EXPECT_TRUE(w.isStanding(0));
}

// The head camera's images reach ROS 2 subscribers of Booster's image topic:
// sensor_msgs Image_, YUYV as "yuv422_yuy2", the bytes the camera system
// rendered, stamped with the simulation time of the capture.
TEST(BoosterEndpoint, HeadCameraImagesGoOutAsRos2Images) {
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  world::Scenario sc = k1Scenario();
  sc.cameras.enabled = true;
  sc.cameras.top = {true, 64, 48, 30.0};
  world::World w(sc);
  sim::Simulation simulation(w, sim::SimulationConfig{});
  booster::EndpointConfig ec;
  // A domain of its own: on ShootKicksTheBallInFrontOfTheK1's (176), which ctest may run beside
  // it, this endpoint (in prepare mode) answered that test's GetMode once.
  ec.robots = {served(0, 180)};
  ec.dds_config = test::sourceDir() / "configs/dds/loopback.xml";
  booster::Endpoint endpoint(w, ec);
  simulation.addSource(endpoint);
  endpoint.attachCameras(simulation);
  std::mutex mutex;
  std::map<uint64_t, std::vector<uint8_t>> rendered;  // by tick
  simulation.addImageSink([&](const world::CameraImage& image) {
    std::lock_guard lock(mutex);
    if (image.camera == world::CameraId::Top) rendered[image.tick] = image.data;
  });
  // A ROS 2 subscriber's default reader: reliable (image_transport's and create_subscription's
  // default, Booster's own vision node's); a best-effort writer never matched it.
  net::Participant participant(loopback(180));
  net::QosSpec q;
  q.reliable = true;
  q.depth = 64;
  net::Reader<sensor_msgs_msg_dds__Image_> reader(participant, sensor_msgs_msg_dds__Image__desc,
                                                  "rt/StereoNetNode/rectified_image", q);
  for (int i = 0; i < 500; ++i) {  // discovery: matched with the robot's image writer
    dds_subscription_matched_status_t matched{};
    dds_get_subscription_matched_status(reader.get(), &matched);
    if (matched.current_count > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  for (int i = 0; i < 40; ++i) {
    simulation.period();
    simulation.flushCameras();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  int got = 0, matched = 0;
  reader.take([&](const sensor_msgs_msg_dds__Image_& m, const dds_sample_info_t&) {
    ++got;
    EXPECT_EQ(m.width, 64u);
    EXPECT_EQ(m.height, 48u);
    EXPECT_STREQ(m.encoding, "yuv422_yuy2");
    EXPECT_EQ(m.step, 128u);
    ASSERT_EQ(m.data._length, 64u * 48u * 2u);
    // The tick from the stamp (10 ms periods), and the same bytes as rendered.
    const double t = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9;
    const auto tick = static_cast<uint64_t>(std::lround(t / 0.01));
    std::lock_guard lock(mutex);
    const auto it = rendered.find(tick);
    if (it != rendered.end() && std::equal(it->second.begin(), it->second.end(), m.data._buffer))
      ++matched;
  });
  std::printf("%d images received, %d equal to the rendered ones, %llu published\n", got, matched,
              (unsigned long long)endpoint.stats(0).images);
  EXPECT_GE(got, 10);  // 30 Hz over 0.4 s: 12 or 13
  EXPECT_EQ(matched, got);
  EXPECT_EQ(endpoint.stats(0).images, rendered.size());
}

// Unmodified team code joins domain 0. A robot served in its own network
// namespace looks like domain 0 there (Cyclone's ExternalDomainId) while this
// process knows it by another id; a client run in the namespace on domain 0
// drives it, and domain 0 outside sees nothing of it. Needs root.
TEST(BoosterEndpoint, ARobotInItsOwnNamespaceIsDomainZeroThere) {
  const char* ip = ::access("/usr/sbin/ip", X_OK) == 0 ? "/usr/sbin/ip" : "/sbin/ip";
  if (::geteuid() != 0 || ::access(ip, X_OK) != 0) GTEST_SKIP() << "needs root and iproute2";
  const std::string ns = "simsoccer-k1t-" + std::to_string(::getpid());
  struct Namespace {
    std::string ip, name;
    Namespace(std::string i, std::string n) : ip(std::move(i)), name(std::move(n)) {
      EXPECT_EQ(std::system((ip + " netns add " + name).c_str()), 0);
      EXPECT_EQ(std::system((ip + " -n " + name + " link set lo up").c_str()), 0);
    }
    ~Namespace() { std::system((ip + " netns delete " + name + " 2>/dev/null").c_str()); }
  } scope(ip, ns);

  booster::BoosterRobot robot = served(0, 177);
  robot.network_namespace = ns;
  ServedK1 k1(robot, /*lockstep=*/true);
  auto& [w, simulation, endpoint] = k1;

  // Outside the namespace, domain 0 has no robot.
  net::Participant outside(loopback(0));
  net::QosSpec q;
  q.reliable = false;
  q.depth = 8;
  net::Reader<booster_interface_msg_dds__LowState_> stranger(
      outside, booster_interface_msg_dds__LowState__desc, "rt/low_state", q);

  const int periods = 200;  // the client turns the head over its first 100
  ClientProcess client({ip, "netns", "exec", ns, SIMSOCCER_BOOSTER_CLIENT, "--domain", "0",
                        "--dds-config", (test::sourceDir() / "configs/dds/loopback.xml").string(),
                        "--periods", std::to_string(periods)});
  ASSERT_TRUE(client.process.started());
  const int status = runUntilTheClientEnds(simulation, endpoint, client);
  const json r = client.result();
  ASSERT_EQ(status, 0) << r.dump();
  EXPECT_NEAR(r.at("head_yaw").get<double>(), 0.4, 0.03);
  EXPECT_EQ(endpoint.stats(0).mode, booster::RobotMode::Custom);
  int seen = 0;
  stranger.take(
      [&](const booster_interface_msg_dds__LowState_&, const dds_sample_info_t&) { ++seen; });
  EXPECT_EQ(seen, 0);
  std::printf("client in %s on domain 0: %llu states, %llu applied; outside: %d states\n",
              ns.c_str(), (unsigned long long)endpoint.stats(0).states_sent,
              (unsigned long long)endpoint.stats(0).applied, seen);
}

// The modes act on the robot: DAMPING lets it fall (joints limp, damped);
// PREPARE stands it again once placed back, and holds the stand pose every
// period, whatever moved its servos meanwhile.
TEST(BoosterEndpoint, DampingDropsTheRobotAndPrepareStandsIt) {
  ServedK1 k1(served(0, 178), /*lockstep=*/false);
  auto& [w, simulation, endpoint] = k1;
  net::Participant client(loopback(178));
  net::QosSpec reliable;
  reliable.depth = 10;
  net::Writer<booster_msgs_msg_dds__RpcReqMsg_> request(
      client, booster_msgs_msg_dds__RpcReqMsg__desc, "rt/LocoApiTopicReq", reliable);
  // Discovery: the service's request reader matched.
  for (int i = 0; i < 500; ++i) {
    dds_publication_matched_status_t matched{};
    dds_get_publication_matched_status(request.get(), &matched);
    if (matched.current_count > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  auto changeMode = [&](int mode) {
    const std::string header = R"({"api_id": 2000, "expect_response": false})";
    const std::string body = json{{"mode", mode}}.dump();
    booster_msgs_msg_dds__RpcReqMsg_ req{};
    req.uuid = const_cast<char*>("test");
    req.header = const_cast<char*>(header.c_str());
    req.body = const_cast<char*>(body.c_str());
    request.write(req);
    for (int i = 0; i < 100 && endpoint.stats(0).mode != static_cast<booster::RobotMode>(mode);
         ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      simulation.period();
    }
    ASSERT_EQ(endpoint.stats(0).mode, static_cast<booster::RobotMode>(mode));
  };
  auto run = [&](double seconds) {
    for (int i = 0; i < static_cast<int>(seconds / 0.01); ++i) simulation.period();
  };
  run(1.0);
  EXPECT_TRUE(w.isStanding(0));
  changeMode(0);  // damping
  run(3.0);
  EXPECT_FALSE(w.isStanding(0));
  changeMode(1);  // prepare: stiff again, but lying; the referee's hands put it back
  w.placeRobot(0, -3.0, 0.0, 0.0, "stand");
  // A placement holds the joints itself; the mode's command follows each period.
  w.setJointTarget(0, w.robot(0).model->body->jointIndex("HeadYaw"), 0.8, 1.0);
  run(3.0);
  EXPECT_TRUE(w.isStanding(0));
  EXPECT_NEAR(
      w.physics().jointPosition(w.robot(0).body, w.robot(0).model->body->jointIndex("HeadYaw")),
      0.0, 0.02);
}

// With the field network (`serve --booster-netns`): the robot's namespace sits
// on a bridge at PREFIX.T.P; the GameController's broadcast reaches a program
// in it, while its DDS stays on the namespace's loopback as domain 0. Root.
TEST(BoosterEndpoint, OnTheFieldNetworkTheGameControllerReachesTheRobotsNamespace) {
  if (::geteuid() != 0 || ::access("/usr/sbin/ip", X_OK) != 0)
    GTEST_SKIP() << "needs root and iproute2";
  lola::FieldNetwork net;
  net.bridge = "sbt" + std::to_string(::getpid() % 100000);  // beside other runs' bridges
  net.prefix = "10.79";
  net.link_prefix = "sbt";
  lola::FieldBridge bridge(net);
  lola::RobotNamespace ns(net, 3, 1);
  booster::BoosterRobot robot = served(0, 179);
  robot.network_namespace = ns.name();
  ServedK1 k1(robot, /*lockstep=*/true);

  // A program in the namespace listening on the GameController's port.
  std::string received;
  std::thread listener([&] {
    const int fd = ::open(("/run/netns/" + ns.name()).c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::setns(fd, CLONE_NEWNET) != 0) return;
    ::close(fd);
    const int s = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    const int one = 1;
    ::setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in any{};
    any.sin_family = AF_INET;
    any.sin_port = htons(3838);
    ::bind(s, reinterpret_cast<const sockaddr*>(&any), sizeof any);
    timeval wait{3, 0};
    ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
    char buffer[512];
    const ssize_t n = ::recv(s, buffer, sizeof buffer, 0);
    if (n > 0) received.assign(buffer, static_cast<size_t>(n));
    // Then a team message to its teammates, broadcast on the team port (10000 + 3).
    ::setsockopt(s, SOL_SOCKET, SO_BROADCAST, &one, sizeof one);
    sockaddr_in team{};
    team.sin_family = AF_INET;
    team.sin_port = htons(10003);
    ::inet_pton(AF_INET, net.broadcast().c_str(), &team.sin_addr);
    const char message[] = "team message";
    ::sendto(s, message, sizeof message, 0, reinterpret_cast<const sockaddr*>(&team), sizeof team);
    ::close(s);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const referee::RuleBook rules =
      referee::loadRuleBook(test::sourceDir() / "configs/rules/hsl_middle_foundation.yaml");
  referee::Game game(rules, {referee::TeamSetup{3, 0, 2, 1}, referee::TeamSetup{4, 1, 3, 1}}, 0);
  referee::GameControllerLinkConfig gc;
  gc.address = net.broadcast();
  gc.return_bind = net.hostAddress();
  gc.return_port = 0;
  gc.team_message_bind = net.broadcast();  // as serve --booster-netns has it
  referee::GameControllerLink link(gc);
  const sim::FieldTeamMessages counted(link, game);
  for (int i = 0; i < 10 && received.empty(); ++i) {
    link.update(game);
    game.advance(0.5);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  listener.join();
  ASSERT_GE(received.size(), 8u);
  EXPECT_EQ(received.substr(0, 4), "RGme");
  EXPECT_EQ(static_cast<uint8_t>(received[4]), 20);  // the HSL's version (RoboCup 2026)
  // The team message counts against team 3's budget, the officials' way (up to 3 s: the
  // broadcast crosses the bridge, and in a parallel test run the cores are busy; 0.4 s once
  // was not enough).
  for (int i = 0; i < 150 && counted.teamMessagesSent(0) == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    link.update(game);
  }
  EXPECT_EQ(counted.teamMessagesSent(0), 1u);
  EXPECT_EQ(counted.teamMessagesSent(1), 0u);

  ClientProcess client({"/usr/sbin/ip", "netns", "exec", ns.name(), SIMSOCCER_BOOSTER_CLIENT,
                        "--domain", "0", "--dds-config",
                        (test::sourceDir() / "configs/dds/loopback.xml").string(), "--periods",
                        "150"});
  ASSERT_TRUE(client.process.started());
  const int status = runUntilTheClientEnds(k1.simulation, k1.endpoint, client);
  ASSERT_EQ(status, 0) << client.result().dump();
  EXPECT_NEAR(client.result().at("head_yaw").get<double>(), 0.4, 0.03);
  std::printf("%s at %s: a %zu-byte RGme v20 packet; the client drove its robot on domain 0\n",
              ns.name().c_str(), ns.address().c_str(), received.size());
}
