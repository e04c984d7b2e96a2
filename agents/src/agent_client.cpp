#include "simsoccer/agents/agent_client.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

namespace simsoccer::agents {

using net::QosSpec;
using Clock = std::chrono::steady_clock;

struct AgentClient::Impl {
  // Samples that reached the game state and team message readers (counted by their listeners,
  // declared before them: they outlive the readers), and the counts when the agent last took
  // from each: a reader nothing reached is not asked, each period (asking costs DDS locks).
  std::atomic<uint64_t> game_arrivals{1}, team_arrivals{1};
  uint64_t game_taken = 0;  // trust_mutex held
  uint64_t team_taken = 0;  // team_mutex held
  std::mutex team_mutex;
  net::Participant participant;
  net::Writer<simsoccer_msg_JoinRequest> join;
  net::Writer<simsoccer_msg_JointCommand> command;
  net::Writer<simsoccer_msg_TeamMessage> team_send;
  net::Reader<simsoccer_msg_SensorFrame> frames;
  net::Reader<simsoccer_msg_RobotStatus> status;
  net::Reader<simsoccer_msg_GameState> game;
  net::Reader<simsoccer_msg_TeamMessage> team_deliver;
  net::Entity waitset, frame_condition;
  std::unique_ptr<net::Reader<simsoccer_msg_CameraImage>> images;  // after subscribeImages()
  net::Entity image_waitset, image_condition;
  // The tick of the last SensorFrame handed to the agent: team messages carry
  // it, so the simulator relays them by when they were sent, not by when they
  // arrived (which varies with the machine's load).
  std::atomic<uint64_t> frame_tick{0};
  // The sightings of the frame receive() returned last (its perception's robots point here).
  std::vector<simsoccer_msg_PerceivedObject> received_robots;
  dds_guid_t me{};  // this agent's participant
  // The simulator once known, and which writers are its (checked once per
  // writer): the DDS receive thread and the agent's thread both ask.
  std::mutex trust_mutex;
  std::optional<dds_guid_t> simulator;
  struct KnownWriter {
    dds_entity_t reader;
    dds_instance_handle_t handle;
    dds_guid_t participant;
  };
  std::vector<KnownWriter> writers;
  std::atomic<uint64_t> foreign{0};
  // The latest GameState of each participant that sent one (a few), until
  // the simulator is known.
  struct GameFrom {
    dds_guid_t participant;
    simsoccer_msg_GameState state;
    uint64_t received;  // order of arrival
  };
  std::vector<GameFrom> games;
  size_t newest_game = 0;
  uint64_t games_received = 0;

  // The participant behind a sample's writer (trust_mutex held).
  bool writerParticipant(dds_entity_t reader, dds_instance_handle_t handle, dds_guid_t& out) {
    for (const KnownWriter& w : writers)
      if (w.reader == reader && w.handle == handle) {
        out = w.participant;
        return true;
      }
    if (!net::publisherParticipant(reader, handle, out)) return false;
    if (writers.size() >= 256) writers.clear();  // strangers' writers come and go
    writers.push_back({reader, handle, out});
    return true;
  }

  Impl(const net::DomainConfig& dds, int team, int player)
      : participant(dds),
        join(participant, simsoccer_msg_JoinRequest_desc, "simsoccer_JoinRequest",
             {true, 4, true, net::robotPartitionName(team, player)}),
        command(participant, simsoccer_msg_JointCommand_desc, "simsoccer_JointCommand",
                {true, 16, false, net::robotPartitionName(team, player)}),
        team_send(participant, simsoccer_msg_TeamMessage_desc, "simsoccer_TeamMessageSend",
                  {true, 16, false, net::robotPartitionName(team, player)}),
        frames(participant, simsoccer_msg_SensorFrame_desc, "simsoccer_SensorFrame",
               {true, 1, false, net::robotPartitionName(team, player)}),
        status(participant, simsoccer_msg_RobotStatus_desc, "simsoccer_RobotStatus",
               {true, 1, true, net::robotPartitionName(team, player)}),
        // Several deep: another participant writing game states now and
        // then (one instance: the topic has no key) does not push the
        // simulator's out before they are taken (a flood still can).
        game(participant, simsoccer_msg_GameState_desc, "simsoccer_GameState", {true, 16, true, ""}),
        team_deliver(participant, simsoccer_msg_TeamMessage_desc, "simsoccer_TeamMessageDeliver",
                     {true, 16, false, net::robotPartitionName(team, player)}) {
    waitset = net::Entity(net::check(dds_create_waitset(participant.get()), "create waitset"));
    frame_condition = net::Entity(
        net::check(dds_create_readcondition(frames.get(), DDS_ANY_STATE), "read condition"));
    net::check(dds_waitset_attach(waitset.get(), frame_condition.get(), 0), "attach");
    countArrivals(game.get(), game_arrivals);
    countArrivals(team_deliver.get(), team_arrivals);
    me = participant.guid();
  }
  static void countArrivals(dds_entity_t reader, std::atomic<uint64_t>& count) {
    dds_listener_t* l = dds_create_listener(&count);
    dds_lset_data_available(l, [](dds_entity_t, void* arg) {
      static_cast<std::atomic<uint64_t>*>(arg)->fetch_add(1, std::memory_order_release);
    });
    net::check(dds_set_listener(reader, l), "set arrival listener");
    dds_delete_listener(l);
  }
  // Whether samples reached a reader since the last call that said so.
  static bool arrivedSince(const std::atomic<uint64_t>& count, uint64_t& taken) {
    const uint64_t now = count.load(std::memory_order_acquire);
    if (now == taken) return false;
    taken = now;
    return true;
  }
};

AgentClient::AgentClient(const net::DomainConfig& dds, int team, int player,
                         std::optional<net::RobotKey> key)
    : team_(team),
      player_(player),
      impl_(std::make_unique<Impl>(dds, team, player)),
      key_(key) {
  if (team < 0 || team > 1 || player < 1 || player > 255)
    throw std::invalid_argument("team must be 0 or 1 and player 1..255");
}

AgentClient::~AgentClient() {
  if (handler_) dds_set_listener(impl_->frames.get(), nullptr);
}

bool AgentClient::fromSimulator(dds_entity_t reader, const dds_sample_info_t& info) {
  std::lock_guard lock(impl_->trust_mutex);
  if (!impl_->simulator) return true;
  dds_guid_t writer;
  if (impl_->writerParticipant(reader, info.publication_handle, writer) &&
      net::sameGuid(writer, *impl_->simulator))
    return true;
  ++impl_->foreign;
  return false;
}

bool AgentClient::knowsSimulator() const {
  std::lock_guard lock(impl_->trust_mutex);
  return impl_->simulator.has_value();
}

int AgentClient::commandReadersMatched() const {
  dds_publication_matched_status_t st{};
  if (dds_get_publication_matched_status(impl_->command.get(), &st) != DDS_RETCODE_OK) return 0;
  return static_cast<int>(st.current_count);
}

uint64_t AgentClient::foreignSamples() const {
  return impl_->foreign;
}

void AgentClient::onFrameData(dds_entity_t reader, void* self) {
  auto* client = static_cast<AgentClient*>(self);
  client->impl_->frames.takeReusing([&](const simsoccer_msg_SensorFrame& f,
                                        const dds_sample_info_t& info) {
    if (f.team == client->team_ && f.player == client->player_ && client->handler_ &&
        client->fromSimulator(reader, info)) {
      client->impl_->frame_tick = f.tick;
      client->handler_(f);
    }
  });
}

void AgentClient::onFrame(FrameHandler handler) {
  if (!handler) {
    dds_set_listener(impl_->frames.get(), nullptr);
    handler_ = nullptr;
    return;
  }
  handler_ = std::move(handler);
  dds_listener_t* l = dds_create_listener(this);
  dds_lset_data_available_arg(l, &AgentClient::onFrameData, this, true);
  net::check(dds_set_listener(impl_->frames.get(), l), "set frame listener");
  dds_delete_listener(l);
  onFrameData(impl_->frames.get(), this);  // frames that came before the listener
}

void AgentClient::readStatus() {
  const dds_entity_t reader = impl_->status.get();
  impl_->status.take([&](const simsoccer_msg_RobotStatus& s, const dds_sample_info_t& info) {
    if (s.team != team_ || s.player != player_ || !fromSimulator(reader, info)) return;
    std::lock_guard lock(impl_->trust_mutex);
    if (!impl_->simulator && s.owned && std::memcmp(s.owner_guid, impl_->me.v, 16) == 0) {
      // Granted: its writer is the simulator (with a key, if it proves it holds it).
      dds_guid_t writer;
      if (!impl_->writerParticipant(reader, info.publication_handle, writer)) return;
      if (key_ && !net::sameProof(net::simulatorProof(*key_, writer, impl_->me), s.proof)) {
        ++impl_->foreign;
        return;
      }
      impl_->simulator = writer;
    }
    status_ = s;
  });
}

bool AgentClient::ownsRobot() const {
  return status_.owned && std::memcmp(status_.owner_guid, impl_->me.v, 16) == 0 && knowsSimulator();
}

bool AgentClient::claim(double timeout_seconds, IfOwned if_owned) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(timeout_seconds));
  // Claim once the simulator's readers of our commands and team messages are
  // matched: a command written before would be lost, and the first ticks
  // would then go differently from run to run.
  const auto matched = [](dds_entity_t writer) {
    dds_publication_matched_status_t st{};
    return dds_get_publication_matched_status(writer, &st) == DDS_RETCODE_OK &&
           st.current_count > 0;
  };
  while (Clock::now() < end && !(matched(impl_->command.get()) && matched(impl_->team_send.get())))
    dds_sleepfor(DDS_MSECS(5));
  // Refusals counted before this claim are somebody else's.
  readStatus();
  const uint32_t refused_before = status_.refused;
  simsoccer_msg_JoinRequest j{};
  j.team = static_cast<uint8_t>(team_);
  j.player = static_cast<uint8_t>(player_);
  if (key_) {
    const net::Proof proof = net::claimProof(*key_, impl_->me);
    std::memcpy(j.proof, proof.data(), sizeof j.proof);
  }
  impl_->join.write(j);
  auto asked = Clock::now();
  while (Clock::now() < end) {
    readStatus();
    if (status_.owned) {
      if (ownsRobot()) return true;
      // Owned by someone else, and the simulator counted our request.
      if (if_owned == IfOwned::Refuse && status_.refused > refused_before) return false;
    } else if (Clock::now() - asked > std::chrono::milliseconds(100)) {
      // Not owned (yet, or released: its owner went away): ask again. The
      // status keeps only the latest sample, so a release can hide the
      // refusal before it; asking again is harmless (the same agent's
      // requests are one claim).
      impl_->join.write(j);
      asked = Clock::now();
    }
    dds_sleepfor(DDS_MSECS(5));
  }
  return false;
}

bool AgentClient::receive(simsoccer_msg_SensorFrame& frame, double timeout_seconds) {
  bool got = false;
  auto grab = [&] {
    impl_->frames.take([&](const simsoccer_msg_SensorFrame& f, const dds_sample_info_t& info) {
      if (f.team == team_ && f.player == player_ && (!got || f.tick > frame.tick) &&
          fromSimulator(impl_->frames.get(), info)) {
        frame = f;
        // The sample's memory goes back to DDS after the take: the sightings
        // are kept here, until the next receive.
        const auto& seen = f.perception.robots;
        impl_->received_robots.assign(seen._buffer, seen._buffer + seen._length);
        frame.perception.robots._buffer = impl_->received_robots.data();
        frame.perception.robots._maximum = seen._length;
        frame.perception.robots._release = false;
        got = true;
      }
    });
  };
  grab();
  if (!got) {
    dds_waitset_wait(impl_->waitset.get(), nullptr, 0,
                     static_cast<dds_duration_t>(timeout_seconds * 1e9));
    grab();
  }
  if (got) impl_->frame_tick = frame.tick;
  readStatus();
  return got;
}

void AgentClient::send(uint64_t tick, std::span<const float> position,
                       std::span<const float> stiffness) {
  constexpr auto n = protocol::kActuators;
  if (position.size() != n || stiffness.size() != n)
    throw std::invalid_argument("a joint command has " + std::to_string(n) + " positions and " +
                                std::to_string(n) + " stiffnesses");
  simsoccer_msg_JointCommand c{};
  c.team = static_cast<uint8_t>(team_);
  c.player = static_cast<uint8_t>(player_);
  c.tick = tick;
  c.serial = ++serial_;
  c.position._buffer = const_cast<float*>(position.data());
  c.position._length = c.position._maximum = n;
  c.stiffness._buffer = const_cast<float*>(stiffness.data());
  c.stiffness._length = c.stiffness._maximum = n;
  impl_->command.write(c);
}

void AgentClient::sendRaw(const simsoccer_msg_JointCommand& command) {
  impl_->command.write(command);
}

bool AgentClient::gameState(simsoccer_msg_GameState& out) {
  const dds_entity_t reader = impl_->game.get();
  std::lock_guard lock(impl_->trust_mutex);
  auto& games = impl_->games;
  if (Impl::arrivedSince(impl_->game_arrivals, impl_->game_taken))
    impl_->game.take([&](const simsoccer_msg_GameState& g, const dds_sample_info_t& info) {
      dds_guid_t from;
      if (!impl_->writerParticipant(reader, info.publication_handle, from)) return;
      if (impl_->simulator && !net::sameGuid(from, *impl_->simulator)) {
        ++impl_->foreign;  // somebody else's game
        return;
      }
      size_t k = 0;
      while (k < games.size() && !net::sameGuid(games[k].participant, from)) ++k;
      if (k == games.size()) {
        if (games.size() < 8) {
          games.push_back({from, {}, 0});
        } else {  // the one heard from longest ago makes room
          k = 0;
          for (size_t i = 1; i < games.size(); ++i)
            if (games[i].received < games[k].received) k = i;
          games[k].participant = from;
        }
      }
      games[k].state = g;
      games[k].received = ++impl_->games_received;
      impl_->newest_game = k;
    });
  // Once the simulator is known, only its game; before, the newest of any.
  if (impl_->simulator) {
    for (const auto& gf : games)
      if (net::sameGuid(gf.participant, *impl_->simulator)) {
        out = gf.state;
        return true;
      }
    return false;
  }
  if (games.empty()) return false;
  out = games[impl_->newest_game].state;
  return true;
}

bool AgentClient::waitForGameState(double timeout_seconds) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(timeout_seconds));
  simsoccer_msg_GameState g;
  while (!gameState(g)) {
    if (Clock::now() >= end) return false;
    dds_sleepfor(DDS_MSECS(5));
  }
  return true;
}

void AgentClient::sendTeamMessage(std::span<const uint8_t> data) {
  if (data.size() > 128) throw std::invalid_argument("team messages are at most 128 bytes");
  simsoccer_msg_TeamMessage m{};
  m.team = static_cast<uint8_t>(team_);
  m.to_player = 0;
  m.from_player = static_cast<uint8_t>(player_);
  m.tick = impl_->frame_tick;
  m.data._buffer = const_cast<uint8_t*>(data.data());
  m.data._length = m.data._maximum = static_cast<uint32_t>(data.size());
  impl_->team_send.write(m);
}

std::vector<TeamMessageIn> AgentClient::receiveTeamMessages() {
  std::vector<TeamMessageIn> out;
  std::lock_guard lock(impl_->team_mutex);
  if (!Impl::arrivedSince(impl_->team_arrivals, impl_->team_taken)) return out;
  impl_->team_deliver.take([&](const simsoccer_msg_TeamMessage& m, const dds_sample_info_t& info) {
    if (m.team != team_ || m.to_player != player_ ||
        !fromSimulator(impl_->team_deliver.get(), info))
      return;
    out.push_back({m.from_player, m.tick,
                   std::vector<uint8_t>(m.data._buffer, m.data._buffer + m.data._length)});
  });
  return out;
}

void AgentClient::subscribeImages() {
  if (impl_->images) return;
  // Two instances (top, bottom) per robot; keep a few of each so a slow
  // reader sees every image of a burst.
  impl_->images = std::make_unique<net::Reader<simsoccer_msg_CameraImage>>(
      impl_->participant, simsoccer_msg_CameraImage_desc, "simsoccer_CameraImage",
      QosSpec{true, 4, false, net::robotPartitionName(team_, player_)});
  impl_->image_waitset =
      net::Entity(net::check(dds_create_waitset(impl_->participant.get()), "create waitset"));
  impl_->image_condition = net::Entity(
      net::check(dds_create_readcondition(impl_->images->get(), DDS_ANY_STATE), "read condition"));
  net::check(dds_waitset_attach(impl_->image_waitset.get(), impl_->image_condition.get(), 0),
             "attach");
}

std::vector<CameraImageIn> AgentClient::receiveImages(double timeout_seconds) {
  if (!impl_->images) throw std::logic_error("receiveImages() before subscribeImages()");
  std::vector<CameraImageIn> out;
  auto grab = [&] {
    impl_->images->take([&](const simsoccer_msg_CameraImage& m, const dds_sample_info_t& info) {
      if (m.team != team_ || m.player != player_ || !fromSimulator(impl_->images->get(), info))
        return;
      CameraImageIn in;
      in.camera = m.camera;
      in.tick = m.tick;
      in.sim_time = m.sim_time;
      in.encoding = m.encoding;
      in.width = m.width;
      in.height = m.height;
      std::copy(std::begin(m.position), std::end(m.position), in.position.begin());
      std::copy(std::begin(m.orientation), std::end(m.orientation), in.orientation.begin());
      std::copy(std::begin(m.intrinsics), std::end(m.intrinsics), in.intrinsics.begin());
      in.data.assign(m.data._buffer, m.data._buffer + m.data._length);
      out.push_back(std::move(in));
    });
  };
  grab();
  if (out.empty() && timeout_seconds > 0) {
    dds_waitset_wait(impl_->image_waitset.get(), nullptr, 0,
                     static_cast<dds_duration_t>(timeout_seconds * 1e9));
    grab();
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const CameraImageIn& a, const CameraImageIn& b) { return a.tick < b.tick; });
  return out;
}

namespace {
PerceivedIn fromMessage(const simsoccer_msg_PerceivedObject& m) {
  PerceivedIn o;
  o.kind = m.kind;
  o.team = m.team == 255 ? -1 : m.team;
  o.in_view = m.in_view != 0;
  o.x = m.position[0];
  o.y = m.position[1];
  o.last_seen = m.last_seen;
  return o;
}
}  // namespace

void perceptionFromMessage(const simsoccer_msg_Perception& m, uint64_t tick, double sim_time,
                           PerceptionIn& out) {
  out.tick = tick;
  out.sim_time = sim_time;
  out.ball = fromMessage(m.ball);
  for (size_t k = 0; k < 4; ++k) out.posts[k] = fromMessage(m.posts[k]);
  out.robots.clear();  // its capacity is kept: no allocation per period
  for (uint32_t i = 0; i < m.robots._length; ++i)
    out.robots.push_back(fromMessage(m.robots._buffer[i]));
  for (size_t k = 0; k < 3; ++k) out.self_pose[k] = m.self_pose[k];
}

bool perceptionFromFrame(const simsoccer_msg_SensorFrame& f, PerceptionIn& out) {
  if (!f.perception.present) return false;
  perceptionFromMessage(f.perception, f.tick, f.sim_time, out);
  return true;
}

}  // namespace simsoccer::agents
