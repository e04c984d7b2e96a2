// A Booster SDK client written for the tests, as a separate process: the
// robot side's contract from a client's view, with the SDK's topic names,
// registered type names and QoS (the C++ SDK's BEST_EFFORT state reader, a
// RELIABLE command writer as Booster's deploy code has, RELIABLE RPC with a
// volatile answer reader). Drives one simulated robot on its own domain:
//   GetMode (prepare), ChangeMode(custom), refused and malformed requests,
//   then answers every LowState with a SERIAL LowCmd that holds the posture
//   it found and turns the head yaw to 0.4 rad, with three bad commands in
//   between (21 entries, PARALLEL, a NaN), then GetMode (custom).
// With --walk it walks the robot with Move instead; with --kick shoot|visual
// it kicks through SOCCER mode (Shoot, or VisualKick with rt/kick_ball).
// Prints one JSON line of what it saw; exit status 0 if every answer was as
// the SDK expects.
#include <dds/dds.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "booster_sdk.h"

namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

dds_entity_t g_participant = 0;

[[noreturn]] void fail(const std::string& why) {
  std::fprintf(stderr, "booster test client: %s\n", why.c_str());
  std::exit(2);
}

dds_entity_t endpoint(bool reader, const dds_topic_descriptor_t* desc, const char* name,
                      bool reliable, int depth) {
  const dds_entity_t topic = dds_create_topic(g_participant, desc, name, nullptr, nullptr);
  if (topic < 0) fail(std::string("topic ") + name);
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_SECS(1));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  const dds_entity_t e = reader ? dds_create_reader(g_participant, topic, q, nullptr)
                                : dds_create_writer(g_participant, topic, q, nullptr);
  dds_delete_qos(q);
  if (e < 0) fail(std::string("endpoint ") + name);
  return e;
}

struct Rpc {
  dds_entity_t request, response;
  int serial = 0;
  // Sends one request and waits up to 5 s for the answer with its uuid. As
  // the SDK's RPC client waits for the service: first until both topics are
  // matched (a request written before would go nowhere, and a volatile answer
  // reader matched late would miss the answer).
  json call(const std::string& header, const std::string& body) {
    const auto matched_by = Clock::now() + std::chrono::seconds(5);
    for (;;) {
      dds_publication_matched_status_t out{};
      dds_subscription_matched_status_t in{};
      dds_get_publication_matched_status(request, &out);
      dds_get_subscription_matched_status(response, &in);
      if (out.current_count > 0 && in.current_count > 0) break;
      if (Clock::now() > matched_by) fail("the locomotion service is not there");
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    const std::string uuid = "test-" + std::to_string(++serial);
    booster_msgs_msg_dds__RpcReqMsg_ req{};
    req.uuid = const_cast<char*>(uuid.c_str());
    req.header = const_cast<char*>(header.c_str());
    req.body = const_cast<char*>(body.c_str());
    if (dds_write(request, &req) < 0) fail("write request");
    const auto end = Clock::now() + std::chrono::seconds(5);
    while (Clock::now() < end) {
      void* samples[1] = {nullptr};
      dds_sample_info_t info[1];
      while (dds_take(response, samples, info, 1, 1) > 0) {
        const auto* r = static_cast<const booster_msgs_msg_dds__RpcRespMsg_*>(samples[0]);
        json answer;
        bool mine = false;
        if (info[0].valid_data && r->uuid && uuid == r->uuid) {
          mine = true;
          answer = {{"status", json::parse(r->header).at("status")},
                    {"body", r->body ? r->body : ""}};
        }
        dds_return_loan(response, samples, 1);
        if (mine) return answer;
        samples[0] = nullptr;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    fail("no answer to " + header);
  }
  json api(int id, const json& body) {
    return call(json{{"api_id", id}, {"expect_response", true}}.dump(), body.dump());
  }
};

}  // namespace

int main(int argc, char** argv) {
  uint32_t domain = 0;
  std::string config;
  int periods = 300;
  double walk = 0.0;       // --walk V: walk with Booster's locomotion API at V m/s instead
  int custom_between = 0;  // with --walk: N LowStates in CUSTOM between two walks
  // --kick shoot|visual: in SOCCER mode, Shoot once, or run the visual kick for --periods
  // LowStates, aimed through rt/kick_ball at --kick-dir (rad from the heading the robot had at
  // the start, which the IMU's yaw tells: the robot frame's dir is that minus the yaw now).
  std::string kick;
  double kick_dir = 0.0;
  int scale = 1;  // --scale N: the waits between calls N times as many LowStates (2 ms periods: 5)
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--domain")
      domain = static_cast<uint32_t>(std::stoul(argv[i + 1]));
    else if (a == "--dds-config")
      config = argv[i + 1];
    else if (a == "--periods")
      periods = std::stoi(argv[i + 1]);
    else if (a == "--walk")
      walk = std::stod(argv[i + 1]);
    else if (a == "--custom-between")
      custom_between = std::stoi(argv[i + 1]);
    else if (a == "--kick")
      kick = argv[i + 1];
    else if (a == "--kick-dir")
      kick_dir = std::stod(argv[i + 1]);
    else if (a == "--scale")
      scale = std::stoi(argv[i + 1]);
  }
  if (!config.empty()) {
    std::ifstream f(config);
    std::stringstream xml;
    xml << f.rdbuf();
    if (dds_create_domain(domain, xml.str().c_str()) < 0) fail("create domain");
  }
  g_participant = dds_create_participant(domain, nullptr, nullptr);
  if (g_participant < 0) fail("create participant");
  const dds_entity_t state =
      endpoint(true, &booster_interface_msg_dds__LowState__desc, "rt/low_state", false, 64);
  // Reliable as Booster's deploy code, 4 deep: two commands sent back to back both arrive.
  const dds_entity_t command =
      endpoint(false, &booster_interface_msg_dds__LowCmd__desc, "rt/joint_ctrl", true, 4);
  Rpc rpc{endpoint(false, &booster_msgs_msg_dds__RpcReqMsg__desc, "rt/LocoApiTopicReq", true, 10),
          endpoint(true, &booster_msgs_msg_dds__RpcRespMsg__desc, "rt/LocoApiTopicResp", true, 10)};

  json out;
  // The latest LowState (waits up to 10 s for a new one).
  std::vector<booster_interface_msg_dds__MotorState_> motors;
  float acc_z = 0, yaw = 0;
  size_t parallel = 0;
  auto nextState = [&](double seconds) {
    const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(seconds));
    while (Clock::now() < end) {
      bool got = false;
      void* samples[1] = {nullptr};
      dds_sample_info_t info[1];
      while (dds_take(state, samples, info, 1, 1) > 0) {
        const auto* s = static_cast<const booster_interface_msg_dds__LowState_*>(samples[0]);
        if (info[0].valid_data) {
          motors.assign(s->motor_state_serial._buffer,
                        s->motor_state_serial._buffer + s->motor_state_serial._length);
          parallel = s->motor_state_parallel._length;
          acc_z = s->imu_state.acc[2];
          yaw = s->imu_state.rpy[2];
          got = true;
        }
        dds_return_loan(state, samples, 1);
        samples[0] = nullptr;
      }
      if (got) return true;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    return false;
  };
  if (!nextState(10.0)) fail("no LowState within 10 s");
  out["motors"] = motors.size();
  out["parallel"] = parallel;
  bool ok = true;
  auto expect = [&](const char* what, const json& answer, int status) {
    out[what] = answer;
    if (answer.at("status") != status) ok = false;
  };
  // The result as one JSON line; the exit status says whether every answer was as expected.
  const auto finish = [&] {
    out["ok"] = ok;
    std::printf("%s\n", out.dump().c_str());
    std::fflush(stdout);
    dds_delete(g_participant);
    return ok ? 0 : 1;
  };
  const json mode = rpc.api(2017, json::object());
  expect("get_mode_first", mode, 0);
  if (json::parse(mode.at("body").get<std::string>()).at("mode") != 1) ok = false;
  if (!kick.empty()) {
    // As team code that kicks with Booster's soccer mode (HULKs, NUbots): SOCCER, then Shoot,
    // or VisualKick started with its direction on rt/kick_ball (reliable, as ROS 2 publishers
    // are), left running, then stopped.
    expect("soccer", rpc.api(2000, {{"mode", 4}}), 0);
    for (int k = 0; k < 100 * scale; ++k) nextState(0.05);  // standing still first
    expect("visual_kick_malformed", rpc.api(2038, {{"start", "yes"}}), 400);
    if (kick == "shoot") {
      // Looking down at the ball first (Shoot takes the foot on the side the robot saw it).
      expect("head_down", rpc.api(2004, {{"pitch", 0.8}, {"yaw", 0.0}}), 0);
      for (int k = 0; k < 50 * scale; ++k) nextState(0.05);
      expect("shoot", rpc.api(2024, json::object()), 0);
      for (int k = 0; k < periods; ++k)
        if (!nextState(5.0)) fail("LowStates stopped after " + std::to_string(k));
    } else {
      const dds_entity_t target =
          endpoint(false, &brain_msg_dds__Kick__desc, "rt/kick_ball", true, 1);
      // A sample written before the writer matches the robot's reader goes nowhere.
      for (auto end = Clock::now() + std::chrono::seconds(5);;) {
        dds_publication_matched_status_t st{};
        dds_get_publication_matched_status(target, &st);
        if (st.current_count > 0) break;
        if (Clock::now() > end) fail("rt/kick_ball: no reader within 5 s");
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      const float start_yaw = yaw;
      expect("visual_kick", rpc.api(2038, {{"start", true}, {"version", 1}}), 0);
      expect("shoot_while_visual_kick", rpc.api(2024, json::object()), 502);
      for (int k = 0; k < periods; ++k) {
        if (k < 300 && k % 100 == 0) {  // three times, as team code repeats its target
          std::string frame = "base_link";
          brain_msg_dds__Kick_ m{};
          m.header.frame_id = frame.data();
          m.dir = kick_dir - (yaw - start_yaw);
          m.power = 6.0;
          if (dds_write(target, &m) < 0) fail("write Kick");
        }
        if (!nextState(5.0)) fail("LowStates stopped after " + std::to_string(k));
      }
      expect("visual_kick_stop", rpc.api(2038, {{"start", false}, {"version", 1}}), 0);
    }
    const json soccer = rpc.api(2017, json::object());
    expect("get_mode_soccer", soccer, 0);
    if (json::parse(soccer.at("body").get<std::string>()).at("mode") != 4) ok = false;
    return finish();
  }
  if (walk != 0.0) {
    // As team code that uses Booster's walk: walking mode, the head turned, Move repeated at
    // about 50 Hz (every 2 LowStates of a 10 ms period) for `periods` LowStates, then a stop.
    expect("walking", rpc.api(2000, {{"mode", 2}}), 0);
    expect("head", rpc.api(2004, {{"pitch", 0.1}, {"yaw", 0.3}}), 0);
    const auto walkFor = [&](int states) {
      for (int k = 0; k < states; ++k) {
        if (k % 2 == 0 &&
            rpc.api(2001, {{"vx", walk}, {"vy", 0.0}, {"vyaw", 0.0}}).at("status") != 0)
          ok = false;
        if (!nextState(5.0)) fail("LowStates stopped after " + std::to_string(k));
      }
      expect("stop", rpc.api(2001, {{"vx", 0.0}, {"vy", 0.0}, {"vyaw", 0.0}}), 0);
    };
    walkFor(periods);
    if (custom_between > 0) {
      // CUSTOM for a while, holding the posture found with the robot's own gains (as team
      // code that switches to its own controller), then walking again.
      for (int k = 0; k < 300; ++k) nextState(0.05);  // the stop settles: feet together
      expect("custom", rpc.api(2000, {{"mode", 3}}), 0);
      if (!nextState(5.0)) fail("no LowState in custom mode");
      std::vector<booster_interface_msg_dds__MotorCmd_> hold(motors.size());
      for (size_t i = 0; i < motors.size(); ++i) {
        hold[i].q = motors[i].q;
        hold[i].kp = i >= 10 ? 300.0f : 40.0f;  // JointIndexK1: 10.. are the legs
        hold[i].kd = i >= 10 ? 6.0f : 1.0f;
        hold[i].weight = 1.0f;
      }
      for (int k = 0; k < custom_between; ++k) {
        booster_interface_msg_dds__LowCmd_ c{};
        c.cmd_type = booster_interface_msg_dds__SERIAL;
        c.motor_cmd._buffer = hold.data();
        c.motor_cmd._length = c.motor_cmd._maximum = static_cast<uint32_t>(hold.size());
        c.motor_cmd._release = false;
        if (dds_write(command, &c) < 0) fail("write LowCmd");
        if (!nextState(5.0)) fail("LowStates stopped in custom mode");
      }
      expect("walking_again", rpc.api(2000, {{"mode", 2}}), 0);
      expect("head_again", rpc.api(2004, {{"pitch", 0.1}, {"yaw", 0.3}}), 0);  // CUSTOM forgot it
      walkFor(periods);
    }
    const json walking = rpc.api(2017, json::object());
    expect("get_mode_walking", walking, 0);
    if (json::parse(walking.at("body").get<std::string>()).at("mode") != 2) ok = false;
    return finish();
  }
  expect("walking", rpc.api(2000, {{"mode", 2}}), 501);
  expect("mode_out_of_range", rpc.api(2000, {{"mode", 9}}), 400);
  expect("garbage_header", rpc.call("{not json", "{}"), 400);
  expect("move", rpc.api(2001, {{"vx", 0.3}, {"vy", 0}, {"vyaw", 0}}), 501);
  expect("custom", rpc.api(2000, {{"mode", 3}}), 0);

  // CUSTOM: hold the posture found, turn the head; answer every LowState.
  if (!nextState(5.0)) fail("no LowState in custom mode");
  const size_t n = motors.size();
  std::vector<float> hold(n);
  for (size_t i = 0; i < n; ++i) hold[i] = motors[i].q;
  std::vector<booster_interface_msg_dds__MotorCmd_> cmd(n);
  auto send = [&](size_t count, booster_interface_msg_dds__CmdType type, float nan_at_head) {
    booster_interface_msg_dds__LowCmd_ c{};
    c.cmd_type = type;
    c.motor_cmd._buffer = cmd.data();
    c.motor_cmd._length = c.motor_cmd._maximum = static_cast<uint32_t>(count);
    c.motor_cmd._release = false;
    const float keep = cmd[0].q;
    if (nan_at_head != 0) cmd[0].q = std::numeric_limits<float>::quiet_NaN();
    if (dds_write(command, &c) < 0) fail("write LowCmd");
    cmd[0].q = keep;
  };
  int answered = 0;
  for (int k = 0; k < periods; ++k) {
    for (size_t i = 0; i < n; ++i) {
      const bool leg = i >= 10;  // JointIndexK1: 10.. are the legs
      cmd[i] = booster_interface_msg_dds__MotorCmd_{};
      cmd[i].q = hold[i];
      cmd[i].kp = leg ? 80.0f : 10.0f;
      cmd[i].kd = leg ? 2.0f : 1.0f;
      cmd[i].weight = 1.0f;
    }
    cmd[0].q = static_cast<float>(0.4 * std::min(1.0, k / 100.0));      // head yaw
    if (k == 50) send(n - 1, booster_interface_msg_dds__SERIAL, 0);     // one entry short
    if (k == 60) send(n, booster_interface_msg_dds__PARALLEL, 0);       // motor space
    send(n, booster_interface_msg_dds__SERIAL, k == 70 ? 1.0f : 0.0f);  // a NaN at 70
    ++answered;
    if (!nextState(5.0)) fail("LowStates stopped after " + std::to_string(k));
  }
  out["answered"] = answered;
  out["acc_z"] = acc_z;  // standing still: the specific force, g up
  out["head_yaw"] = motors.at(0).q;
  const json custom = rpc.api(2017, json::object());
  expect("get_mode_custom", custom, 0);
  if (json::parse(custom.at("body").get<std::string>()).at("mode") != 3) ok = false;
  return finish();
}
