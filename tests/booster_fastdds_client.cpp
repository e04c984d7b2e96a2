// A Booster SDK client on Fast DDS, the middleware the SDK itself bundles (Debian's Fast DDS
// 2.9; the SDK has 2.13): the message types written as the SDK's fastddsgen-2-style classic-CDR
// types, registered under the SDK's names, without type objects; the participant from the
// profile "booster_dds" in $FASTRTPS_DEFAULT_PROFILES_FILE as the SDK's ChannelFactory makes it.
// Against simsoccer's Cyclone endpoint: reads LowStates, asks GetMode, switches to CUSTOM, turns
// the head yaw to 0.4 rad with LowCmds, asks GetMode again. Prints one JSON line; exit 0 if
// every answer was as expected.
#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace eprosima::fastdds::dds;
using eprosima::fastcdr::Cdr;
using eprosima::fastcdr::FastBuffer;
using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

// The SDK's messages (include/booster/idl/b1/*.h), members in its order.
struct MotorState {
  uint8_t mode = 0;
  float q = 0, dq = 0, ddq = 0, tau_est = 0;
  uint8_t temperature = 0;
  uint32_t lost = 0;
  uint32_t reserve[2] = {0, 0};
};
struct LowState {
  float rpy[3]{}, gyro[3]{}, acc[3]{};
  std::vector<MotorState> parallel, serial;
};
struct MotorCmd {
  uint8_t mode = 0;
  float q = 0, dq = 0, tau = 0, kp = 0, kd = 0, weight = 0;
};
struct LowCmd {
  uint32_t cmd_type = 1;  // SERIAL
  std::vector<MotorCmd> motor_cmd;
};
struct Rpc {
  std::string uuid, header, body;
};

// A classic-CDR type under a given name, serialised by two functions.
template <class T>
class CdrType : public TopicDataType {
 public:
  using Write = std::function<void(Cdr&, const T&)>;
  using Read = std::function<void(Cdr&, T&)>;
  CdrType(const char* name, Write w, Read r) : write_(std::move(w)), read_(std::move(r)) {
    setName(name);
    m_typeSize = 64 * 1024;
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, SerializedPayload_t* payload) override {
    FastBuffer fb(reinterpret_cast<char*>(payload->data), payload->max_size);
    Cdr ser(fb, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
    payload->encapsulation = ser.endianness() == Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
    try {
      ser.serialize_encapsulation();
      write_(ser, *static_cast<const T*>(data));
    } catch (...) {
      return false;
    }
    payload->length = static_cast<uint32_t>(ser.getSerializedDataLength());
    return true;
  }
  bool deserialize(SerializedPayload_t* payload, void* data) override {
    FastBuffer fb(reinterpret_cast<char*>(payload->data), payload->length);
    Cdr deser(fb, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
    try {
      deser.read_encapsulation();
      payload->encapsulation = deser.endianness() == Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
      read_(deser, *static_cast<T*>(data));
    } catch (...) {
      return false;
    }
    return true;
  }
  std::function<uint32_t()> getSerializedSizeProvider(void*) override {
    return [] { return 64u * 1024u; };
  }
  void* createData() override { return new T(); }
  void deleteData(void* data) override { delete static_cast<T*>(data); }
  bool getKey(void*, InstanceHandle_t*, bool) override { return false; }

 private:
  Write write_;
  Read read_;
};

void readMotor(Cdr& c, MotorState& m) {
  c >> m.mode >> m.q >> m.dq >> m.ddq >> m.tau_est >> m.temperature >> m.lost >> m.reserve[0] >>
      m.reserve[1];
}
void readMotors(Cdr& c, std::vector<MotorState>& v) {
  uint32_t n = 0;
  c >> n;
  if (n > 1000) throw std::runtime_error("sequence too long");
  v.resize(n);
  for (auto& m : v) readMotor(c, m);
}

[[noreturn]] void fail(const std::string& why) {
  std::fprintf(stderr, "booster fastdds client: %s\n", why.c_str());
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  uint32_t domain = 0;
  int periods = 200;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--domain")
      domain = static_cast<uint32_t>(std::stoul(argv[i + 1]));
    else if (a == "--periods")
      periods = std::stoi(argv[i + 1]);
  }
  auto* factory = DomainParticipantFactory::get_instance();
  // As the SDK: the profile "booster_dds" from $FASTRTPS_DEFAULT_PROFILES_FILE.
  DomainParticipant* participant = factory->create_participant_with_profile(domain, "booster_dds");
  if (!participant)
    fail("no participant from profile booster_dds ($FASTRTPS_DEFAULT_PROFILES_FILE)");

  TypeSupport state_type(new CdrType<LowState>(
      "booster_interface::msg::dds_::LowState_", [](Cdr&, const LowState&) {},
      [](Cdr& c, LowState& s) {
        for (float& v : s.rpy) c >> v;
        for (float& v : s.gyro) c >> v;
        for (float& v : s.acc) c >> v;
        readMotors(c, s.parallel);
        readMotors(c, s.serial);
      }));
  TypeSupport cmd_type(new CdrType<LowCmd>(
      "booster_interface::msg::dds_::LowCmd_",
      [](Cdr& c, const LowCmd& l) {
        c << l.cmd_type << static_cast<uint32_t>(l.motor_cmd.size());
        for (const MotorCmd& m : l.motor_cmd)
          c << m.mode << m.q << m.dq << m.tau << m.kp << m.kd << m.weight;
      },
      [](Cdr&, LowCmd&) {}));
  auto rpcWrite = [](Cdr& c, const Rpc& r) { c << r.uuid << r.header << r.body; };
  auto rpcRead = [](Cdr& c, Rpc& r) { c >> r.uuid >> r.header >> r.body; };
  TypeSupport req_type(new CdrType<Rpc>("booster_msgs::msg::dds_::RpcReqMsg_", rpcWrite, rpcRead));
  TypeSupport resp_type(
      new CdrType<Rpc>("booster_msgs::msg::dds_::RpcRespMsg_", rpcWrite, rpcRead));
  for (TypeSupport* t : {&state_type, &cmd_type, &req_type, &resp_type})
    if (t->register_type(participant) != ReturnCode_t::RETCODE_OK) fail("register type");

  Subscriber* sub = participant->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  Publisher* pub = participant->create_publisher(PUBLISHER_QOS_DEFAULT);
  // The SDK's QoS: state readers best effort (depth 64), RPC reliable (the C++ SDK's volatile
  // answer reader), commands with Fast DDS' default writer QoS (reliable).
  DataReaderQos state_qos = DATAREADER_QOS_DEFAULT;
  state_qos.reliability().kind = BEST_EFFORT_RELIABILITY_QOS;
  state_qos.history().kind = KEEP_LAST_HISTORY_QOS;
  state_qos.history().depth = 64;
  DataReaderQos resp_qos = DATAREADER_QOS_DEFAULT;
  resp_qos.reliability().kind = RELIABLE_RELIABILITY_QOS;
  resp_qos.history().depth = 10;
  DataWriterQos req_qos = DATAWRITER_QOS_DEFAULT;
  req_qos.history().depth = 10;
  DataReader* state = sub->create_datareader(
      participant->create_topic("rt/low_state", state_type.get_type_name(), TOPIC_QOS_DEFAULT),
      state_qos);
  DataWriter* command = pub->create_datawriter(
      participant->create_topic("rt/joint_ctrl", cmd_type.get_type_name(), TOPIC_QOS_DEFAULT),
      DATAWRITER_QOS_DEFAULT);
  DataWriter* request = pub->create_datawriter(
      participant->create_topic("rt/LocoApiTopicReq", req_type.get_type_name(), TOPIC_QOS_DEFAULT),
      req_qos);
  DataReader* response = sub->create_datareader(
      participant->create_topic("rt/LocoApiTopicResp", resp_type.get_type_name(),
                                TOPIC_QOS_DEFAULT),
      resp_qos);
  if (!state || !command || !request || !response) fail("create readers and writers");

  LowState last;
  auto nextState = [&](double seconds) {
    const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(seconds));
    while (Clock::now() < end) {
      bool got = false;
      LowState s;
      SampleInfo info;
      while (state->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK)
        if (info.valid_data) {
          last = s;
          got = true;
        }
      if (got) return true;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    return false;
  };
  int serial = 0;
  auto call = [&](int api, const json& body) {
    Rpc req{"fastdds-" + std::to_string(++serial),
            json{{"api_id", api}, {"expect_response", true}}.dump(), body.dump()};
    // As the SDK's RPC client waits for the service: until both topics are
    // matched (a request written before would go nowhere, and a volatile
    // answer reader matched late would miss the answer).
    const auto end = Clock::now() + std::chrono::seconds(10);
    for (;;) {
      PublicationMatchedStatus out;
      SubscriptionMatchedStatus in;
      request->get_publication_matched_status(out);
      response->get_subscription_matched_status(in);
      if ((out.current_count > 0 && in.current_count > 0) || Clock::now() >= end) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    request->write(&req);
    while (Clock::now() < end) {
      Rpc r;
      SampleInfo info;
      while (response->take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
        if (info.valid_data && r.uuid == req.uuid)
          return json{{"status", json::parse(r.header).at("status")}, {"body", r.body}};
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    fail("no answer to api " + std::to_string(api));
  };

  if (!nextState(15.0)) fail("no LowState within 15 s");
  json out;
  out["motors"] = last.serial.size();
  bool ok = last.serial.size() == 22;
  const json first = call(2017, json::object());
  out["get_mode_first"] = first;
  ok = ok && first.at("status") == 0 &&
       json::parse(first.at("body").get<std::string>()).at("mode") == 1;
  const json custom = call(2000, {{"mode", 3}});
  out["custom"] = custom;
  ok = ok && custom.at("status") == 0;
  if (!nextState(5.0)) fail("no LowState in custom mode");
  std::vector<float> hold;
  for (const MotorState& m : last.serial) hold.push_back(m.q);
  LowCmd cmd;
  cmd.motor_cmd.resize(hold.size());
  for (int k = 0; k < periods; ++k) {
    for (size_t i = 0; i < hold.size(); ++i) {
      const bool leg = i >= 10;
      cmd.motor_cmd[i] = MotorCmd{0, hold[i], 0, 0, leg ? 80.0f : 10.0f, leg ? 2.0f : 1.0f, 1.0f};
    }
    cmd.motor_cmd[0].q = static_cast<float>(0.4 * std::min(1.0, k / 50.0));
    command->write(&cmd);
    if (!nextState(5.0)) fail("LowStates stopped after " + std::to_string(k));
  }
  out["head_yaw"] = last.serial.at(0).q;
  out["acc_z"] = last.acc[2];
  const json again = call(2017, json::object());
  out["get_mode_custom"] = again;
  ok = ok && json::parse(again.at("body").get<std::string>()).at("mode") == 3;
  out["ok"] = ok;
  std::printf("%s\n", out.dump().c_str());
  std::fflush(stdout);
  participant->delete_contained_entities();
  factory->delete_participant(participant);
  return ok ? 0 : 1;
}
