#include "simsoccer/net/sim_server.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <exception>
#include <random>
#include <thread>
#include <tuple>
#include <utility>

#include "simsoccer/world/match_log.hpp"

namespace simsoccer::net {

using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// Reliable, latest sample per instance: frames, clock, status.
QosSpec latest() {
  return {true, 1, false, ""};
}
QosSpec latestDurable() {
  return {true, 1, true, ""};
}

}  // namespace

void toMessage(const referee::ControlData& d, uint64_t tick, simsoccer_msg_GameState& m) {
  m.packet_number = d.packet_number;
  m.players_per_team = d.players_per_team;
  m.competition_phase = d.competition_phase;
  m.competition_type = d.competition_type;
  m.game_phase = d.game_phase;
  m.state = d.state;
  m.set_play = d.set_play;
  m.first_half = d.first_half;
  m.kicking_team = d.kicking_team;
  m.secs_remaining = d.secs_remaining;
  m.secondary_time = d.secondary_time;
  for (size_t t = 0; t < 2; ++t) {
    const referee::TeamInfo& in = d.teams[t];
    simsoccer_msg_TeamInfo& out = m.teams[t];
    out.team_number = in.team_number;
    out.field_player_colour = in.field_player_colour;
    out.goalkeeper_colour = in.goalkeeper_colour;
    out.goalkeeper = in.goalkeeper;
    out.score = in.score;
    out.penalty_shot = in.penalty_shot;
    out.single_shots = in.single_shots;
    out.message_budget = in.message_budget;
    for (size_t p = 0; p < referee::gc::kMaxPlayers; ++p) {
      out.players[p].penalty = in.players[p].penalty;
      out.players[p].secs_till_unpenalised = in.players[p].secs_till_unpenalised;
    }
  }
  m.tick = tick;
}

void toMessage(const world::SensorFrame& f, int team, int player, simsoccer_msg_SensorFrame& m) {
  m.team = static_cast<uint8_t>(team);
  m.player = static_cast<uint8_t>(player);
  m.tick = f.tick;
  m.sim_time = f.time;
  std::memcpy(m.position, f.position.data(), sizeof m.position);
  std::memcpy(m.velocity, f.velocity.data(), sizeof m.velocity);
  std::memcpy(m.target, f.target.data(), sizeof m.target);
  std::memcpy(m.stiffness, f.stiffness.data(), sizeof m.stiffness);
  std::memcpy(m.current, f.current.data(), sizeof m.current);
  std::memcpy(m.temperature, f.temperature.data(), sizeof m.temperature);
  std::memcpy(m.status, f.status.data(), sizeof m.status);
  std::memcpy(m.accelerometer, f.accelerometer.data(), sizeof m.accelerometer);
  std::memcpy(m.gyroscope, f.gyroscope.data(), sizeof m.gyroscope);
  std::memcpy(m.angles, f.angles.data(), sizeof m.angles);
  std::memcpy(m.fsr, f.fsr.data(), sizeof m.fsr);
  std::memcpy(m.foot_weight, f.foot_weight.data(), sizeof m.foot_weight);
  for (int foot = 0; foot < 2; ++foot)
    for (int k = 0; k < 2; ++k) m.centre_of_pressure[2 * foot + k] = f.centre_of_pressure[foot][k];
  std::memcpy(m.sonar, f.sonar.data(), sizeof m.sonar);
  for (int s = 0; s < 2; ++s)
    for (int e = 0; e < 10; ++e) m.sonar_echoes[10 * s + e] = f.sonar_echoes[s][e];
  std::memcpy(m.sonar_echo_count, f.sonar_echo_count.data(), sizeof m.sonar_echo_count);
  std::memcpy(m.touch, f.touch.data(), sizeof m.touch);
}

void toMessage(const world::CameraImage& image, simsoccer_msg_CameraImage& m) {
  m.team = static_cast<uint8_t>(image.team);
  m.player = static_cast<uint8_t>(image.number);
  m.camera = static_cast<uint8_t>(image.camera);
  m.tick = image.tick;
  m.sim_time = image.sim_time;
  m.encoding = static_cast<uint8_t>(image.encoding);
  m.width = static_cast<uint16_t>(image.view.width);
  m.height = static_cast<uint16_t>(image.view.height);
  const engine::Vec3 p = image.view.pose.translation();
  const Eigen::Quaterniond q(image.view.pose.linear());
  for (int k = 0; k < 3; ++k) m.position[k] = static_cast<float>(p[k]);
  m.orientation[0] = static_cast<float>(q.x());
  m.orientation[1] = static_cast<float>(q.y());
  m.orientation[2] = static_cast<float>(q.z());
  m.orientation[3] = static_cast<float>(q.w());
  m.intrinsics[0] = static_cast<float>(image.view.fx);
  m.intrinsics[1] = static_cast<float>(image.view.fy);
  m.intrinsics[2] = static_cast<float>(image.view.cx);
  m.intrinsics[3] = static_cast<float>(image.view.cy);
  m.data._buffer = const_cast<uint8_t*>(image.data.data());  // not owned, not released
  m.data._length = static_cast<uint32_t>(image.data.size());
  m.data._maximum = m.data._length;
  m.data._release = false;
}

namespace {
simsoccer_msg_PerceivedObject toMessage(const world::PerceivedObject& o) {
  simsoccer_msg_PerceivedObject m{};
  m.kind = static_cast<uint8_t>(o.kind);
  m.team = o.team < 0 ? 255 : static_cast<uint8_t>(o.team);
  m.in_view = o.in_view;
  m.camera = o.camera < 0 ? 255 : static_cast<uint8_t>(o.camera);
  m.position[0] = static_cast<float>(o.x);
  m.position[1] = static_cast<float>(o.y);
  m.last_seen = o.last_seen;
  return m;
}
}  // namespace

void toMessage(const world::Perception& p, simsoccer_msg_Perception& m,
               std::vector<simsoccer_msg_PerceivedObject>& scratch) {
  m.present = 1;
  m.ball = toMessage(p.ball);
  for (size_t k = 0; k < 4; ++k) m.posts[k] = toMessage(p.posts[k]);
  scratch.clear();
  for (const auto& r : p.robots) {
    if (scratch.size() >= 40) break;
    scratch.push_back(toMessage(r));
  }
  m.robots._buffer = scratch.data();
  m.robots._length = m.robots._maximum = static_cast<uint32_t>(scratch.size());
  m.robots._release = false;
  m.self_pose[0] = static_cast<float>(p.self_x);
  m.self_pose[1] = static_cast<float>(p.self_y);
  m.self_pose[2] = static_cast<float>(p.self_yaw);
}

struct SimServer::Impl {
  Participant participant;
  // A robot's own topics, written in its partition (robot_<team>_<player>):
  // only its agent gets them. (The status and the team messages went to every
  // agent before, which threw away all but its own: at 22 robots 484 status
  // samples a second; 11 v 11, 4,840 team message samples.)
  struct RobotWriters {
    RobotWriters(Participant& p, const std::string& partition, bool with_images)
        : frame(p, simsoccer_msg_SensorFrame_desc, "simsoccer_SensorFrame",
                QosSpec{true, 1, false, partition}),
          status(p, simsoccer_msg_RobotStatus_desc, "simsoccer_RobotStatus",
                 QosSpec{true, 1, true, partition}),
          team_deliver(p, simsoccer_msg_TeamMessage_desc, "simsoccer_TeamMessageDeliver",
                       QosSpec{true, 16, false, partition}) {
      if (with_images)
        images = std::make_unique<Writer<simsoccer_msg_CameraImage>>(
            p, simsoccer_msg_CameraImage_desc, "simsoccer_CameraImage",
            QosSpec{true, 1, false, partition});
    }
    Writer<simsoccer_msg_SensorFrame> frame;
    Writer<simsoccer_msg_RobotStatus> status;
    Writer<simsoccer_msg_TeamMessage> team_deliver;             // messages to this robot
    std::unique_ptr<Writer<simsoccer_msg_CameraImage>> images;  // cameras on (both)
  };
  std::vector<std::unique_ptr<RobotWriters>> robot_writers;  // world order
  Writer<simsoccer_msg_SimClock> clock;
  Writer<simsoccer_msg_GameState> game;
  std::unique_ptr<Writer<simsoccer_msg_WorldTruth>> truth;
  Reader<simsoccer_msg_JointCommand> commands;
  Reader<simsoccer_msg_JoinRequest> joins;
  Reader<simsoccer_msg_TeamMessage> team_send;
  Entity waitset;
  Entity join_condition;
  // Writers seen on the command and team-message readers: their participant
  // and partition (cached: looked up once per writer).
  struct Publisher {
    dds_instance_handle_t handle;
    dds_guid_t participant;
    std::string partition;
  };
  std::vector<Publisher> publishers;
  // Team messages waiting for their delivery tick (one per message sent).
  struct Pending {
    uint64_t due;
    simsoccer_msg_TeamMessage msg;
    std::array<uint8_t, 128> data;
  };
  std::deque<Pending> pending;
  std::mt19937_64 loss_rng;
  std::vector<simsoccer_msg_RobotTruth> truth_robots;  // reused every period
  simsoccer_msg_GameState game_state{};
  double game_state_published_at = -1e9;
  bool game_state_set = false;  // a referee has set one (then it repeats at 2 Hz)
  // This period's frames (perception in them, `perceived` holding each
  // one's sightings) and clock, written by writeFrames.
  std::vector<simsoccer_msg_SensorFrame> frames_out;
  std::vector<std::vector<simsoccer_msg_PerceivedObject>> perceived;
  simsoccer_msg_SimClock clock_out{};
  // Pipelined periods: the frames go out on this thread while the world
  // steps (each write also runs the loopback path into its agent's socket
  // and wakes it: 8 us of CPU or more). Started with the first such period.
  std::thread sender;
  std::mutex send_mutex;
  std::condition_variable send_cv;
  bool send_due = false, send_stop = false;
  std::exception_ptr send_error;  // a write that failed on the sender, rethrown by framesOut

  void writeFrames() {
    for (size_t r = 0; r < frames_out.size(); ++r) robot_writers[r]->frame.write(frames_out[r]);
    clock.write(clock_out);
  }
  void sendLoop() {
    std::unique_lock lock(send_mutex);
    for (;;) {
      send_cv.wait(lock, [&] { return send_due || send_stop; });
      if (!send_due) return;  // stopped, nothing left to write
      lock.unlock();
      std::exception_ptr error;
      try {
        writeFrames();
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      if (error && !send_error) send_error = error;
      send_due = false;
      send_cv.notify_all();
    }
  }
  // Waits until the frames handed to the sender are written; a write that
  // failed there fails here.
  void framesOut() {
    std::unique_lock lock(send_mutex);
    send_cv.wait(lock, [&] { return !send_due; });
    if (send_error) std::rethrow_exception(std::exchange(send_error, nullptr));
  }
  void sendInBackground() {
    if (!sender.joinable()) sender = std::thread([this] { sendLoop(); });
    std::lock_guard lock(send_mutex);
    send_due = true;
    send_cv.notify_all();
  }
  ~Impl() {
    if (!sender.joinable()) return;
    {
      std::lock_guard lock(send_mutex);
      send_stop = true;  // after the frames due, if any
    }
    send_cv.notify_all();
    sender.join();
  }

  explicit Impl(const ServerConfig& c, uint64_t seed)
      : participant(c.dds),
        clock(participant, simsoccer_msg_SimClock_desc, "simsoccer_SimClock", latest()),
        game(participant, simsoccer_msg_GameState_desc, "simsoccer_GameState", latestDurable()),
        commands(participant, simsoccer_msg_JointCommand_desc, "simsoccer_JointCommand",
                 {true, 16, false, kAllRobotPartitions}),
        joins(participant, simsoccer_msg_JoinRequest_desc, "simsoccer_JoinRequest",
              {true, 4, true, kAllRobotPartitions}),
        team_send(participant, simsoccer_msg_TeamMessage_desc, "simsoccer_TeamMessageSend",
                  {true, 16, false, kAllRobotPartitions}),
        loss_rng(seed) {
    waitset = Entity(check(dds_create_waitset(participant.get()), "create waitset"));
    join_condition =
        Entity(check(dds_create_readcondition(joins.get(), DDS_ANY_STATE), "read condition"));
    check(dds_waitset_attach(waitset.get(), join_condition.get(), 1), "attach");
  }

  // The participant of a sample's writer, if that writer writes in the
  // partition of the robot the sample is for (DDS Security's permissions
  // grant a team's agents only their robots' partitions).
  bool participantOf(dds_entity_t reader, dds_instance_handle_t h, int team, int player,
                     dds_guid_t& guid) {
    const Publisher* known = nullptr;
    for (const Publisher& p : publishers)
      if (p.handle == h) known = &p;
    if (!known) {
      Publisher p{h, {}, {}};
      if (!publisherParticipant(reader, h, p.participant, p.partition)) return false;
      if (publishers.size() >= 4096) publishers.clear();  // strangers' writers come and go
      publishers.push_back(std::move(p));
      known = &publishers.back();
    }
    guid = known->participant;
    return known->partition == robotPartitionName(team, player);
  }
};

SimServer::SimServer(sim::Simulation& sim, const ServerConfig& config)
    : sim_(sim),
      world_(sim.world()),
      config_(config),
      ticks_per_second_(static_cast<uint64_t>(
          std::max(1L, std::lround(1.0 / sim.world().scenario().physics.control_period)))) {
  world::World& world = world_;
  impl_ = std::make_unique<Impl>(config, world.scenario().seed ^ 0x7EA3u);
  if (config.world_truth)
    impl_->truth = std::make_unique<Writer<simsoccer_msg_WorldTruth>>(
        impl_->participant, simsoccer_msg_WorldTruth_desc, "simsoccer_WorldTruth", latest());
  for (world::RobotId r = 0; r < world.robotCount(); ++r) {
    const auto& info = world.robot(r);
    RobotSlot slot;
    slot.team = info.team;
    slot.player = info.number;
    if (config.reserve) slot.key = robotKey(*config.reserve, info.team, info.number);
    robots_.push_back(slot);
    impl_->robot_writers.push_back(std::make_unique<Impl::RobotWriters>(
        impl_->participant, robotPartitionName(info.team, info.number),
        world.scenario().cameras.enabled));
    publishStatus(r);
  }
  sim.addSource(*this);
  if (world.scenario().cameras.enabled)
    // On the simulation's conversion thread; DDS writers are thread-safe.
    sim.addImageSink([this](const world::CameraImage& image) {
      simsoccer_msg_CameraImage m{};
      toMessage(image, m);
      impl_->robot_writers[image.robot]->images->write(m);
    });
  // No GameState until a referee sets one: agents without one play freely.
  // Commands are taken as they arrive, in the DDS receive thread: the main
  // thread wakes once, when the last owned robot has answered.
  dds_listener_t* l = dds_create_listener(this);
  dds_lset_data_available_arg(l, &SimServer::onCommands, this, true);
  check(dds_set_listener(impl_->commands.get(), l), "set command listener");
  dds_delete_listener(l);
}

void SimServer::onCommands(dds_entity_t, void* self) {
  auto* server = static_cast<SimServer*>(self);
  std::lock_guard lock(server->mutex_);
  server->handleCommands();
  if (server->expected_tick_ != UINT64_MAX && server->allOwnedAnswered())
    server->answered_.notify_one();
}

bool SimServer::allOwnedAnswered() const {
  for (const RobotSlot& s : robots_)
    if (s.stats.owned && !s.has_command) return false;
  return true;
}

RobotNetStats SimServer::stats(world::RobotId r) const {
  std::lock_guard lock(mutex_);
  RobotNetStats st = robots_.at(r).stats;
  const sim::CommandStats c = sim_.commandStats(r);
  st.accepted = c.accepted;
  st.missed = c.missed;
  st.rejected = c.rejected + robots_.at(r).wrong_tick;
  return st;
}

SimServer::~SimServer() {
  dds_set_listener(impl_->commands.get(), nullptr);
  // Images still queued in the simulation's cameras go to writers that are
  // about to go: deliver them now.
  sim_.flushCameras();
}

int SimServer::robotIndex(int team, int player) const {
  for (size_t i = 0; i < robots_.size(); ++i)
    if (robots_[i].team == team && robots_[i].player == player) {
      for (world::RobotId r : config_.not_served)
        if (r == i) return -1;
      return static_cast<int>(i);
    }
  return -1;
}

size_t SimServer::ownedCount() const {
  std::lock_guard lock(mutex_);
  size_t n = 0;
  for (const RobotSlot& s : robots_) n += s.stats.owned;
  return n;
}

void SimServer::setGameState(const simsoccer_msg_GameState& state) {
  impl_->game_state = state;
  impl_->game_state_set = true;
  impl_->game_state.tick = world_.controlTick();
  impl_->game.write(impl_->game_state);
  impl_->game_state_published_at = world_.time();
}

void SimServer::publishGameState(referee::ControlData data, int /*left_team*/) {
  if (published_game_ && data == *published_game_) return;  // SimServer repeats it at 2 Hz
  simsoccer_msg_GameState m{};
  toMessage(data, world_.controlTick(), m);
  setGameState(m);
  published_game_ = data;
}

void SimServer::publishStatus(world::RobotId r) {
  const RobotSlot& s = robots_[r];
  const sim::CommandStats c = sim_.commandStats(r);
  simsoccer_msg_RobotStatus m{};
  m.team = static_cast<uint8_t>(s.team);
  m.player = static_cast<uint8_t>(s.player);
  m.owned = s.stats.owned;
  std::memcpy(m.owner_guid, s.owner.v, sizeof m.owner_guid);
  m.accepted = static_cast<uint32_t>(c.accepted);
  m.rejected = static_cast<uint32_t>(c.rejected + s.wrong_tick);
  m.refused = static_cast<uint32_t>(s.stats.refused);
  m.missed = static_cast<uint32_t>(c.missed);
  if (s.key && s.stats.owned) {
    const Proof proof = simulatorProof(*s.key, impl_->participant.guid(), s.owner);
    std::memcpy(m.proof, proof.data(), sizeof m.proof);
  }
  impl_->robot_writers[r]->status.write(m);
}

void SimServer::release(world::RobotId r) {
  RobotSlot& s = robots_[r];
  s.stats.owned = false;
  s.owner = {};
  s.owner_join = 0;
  s.has_command = false;
  sim_.dropPending(r);
  const auto& info = world_.robot(r);
  const auto& joints = info.model->body->joints;
  for (size_t j = 0; j < joints.size(); ++j) {
    if (joints[j].motor < 0) continue;
    const int ji = static_cast<int>(j);
    // Hold: keep today's angles as targets; limp: no drive at all.
    world_.setJointTarget(r, ji, world_.jointPosition(r, ji), config_.hold_on_release ? 1.0 : 0.0);
  }
  publishStatus(r);
}

bool SimServer::releaseRobot(world::RobotId r) {
  std::lock_guard lock(mutex_);
  if (!robots_.at(r).stats.owned) return false;
  release(r);
  return true;
}

void SimServer::handleJoins() {
  impl_->joins.take([&](const simsoccer_msg_JoinRequest& j, const dds_sample_info_t& info) {
    const int ri = robotIndex(j.team, j.player);
    if (ri < 0) return;
    RobotSlot& s = robots_[static_cast<size_t>(ri)];
    dds_guid_t guid;
    std::string partition;
    if (!publisherParticipant(impl_->joins.get(), info.publication_handle, guid, partition)) return;
    if (partition != robotPartitionName(j.team, j.player)) {
      ++s.stats.refused;  // a claim written outside the robot's partition
      ++s.stats.unauthorised;
    } else if (s.key && !sameProof(claimProof(*s.key, guid), j.proof)) {
      ++s.stats.refused;  // reserved, and this claimant cannot prove it holds the key
      ++s.stats.unauthorised;
    } else if (!s.stats.owned) {
      s.stats.owned = true;
      s.owner = guid;
      s.owner_join = info.publication_handle;
      s.last_tick = 0;
    } else if (!sameGuid(s.owner, guid)) {
      ++s.stats.refused;  // owned by another agent
    }
    publishStatus(static_cast<world::RobotId>(ri));
  });
}

void SimServer::checkOwners() {
  dds_subscription_matched_status_t st;
  if (dds_get_subscription_matched_status(impl_->joins.get(), &st) < 0) return;
  if (st.current_count_change == 0 && st.total_count_change == 0) return;
  for (size_t r = 0; r < robots_.size(); ++r)
    if (robots_[r].stats.owned && !publicationMatched(impl_->joins.get(), robots_[r].owner_join))
      release(static_cast<world::RobotId>(r));
}

void SimServer::handleCommands() {
  const bool lockstep = config_.lockstep;
  // Lockstep: the tick just published; real time: the newest published.
  const uint64_t tick = lockstep ? expected_tick_ : published_tick_;
  impl_->commands.takeReusing([&](const simsoccer_msg_JointCommand& c,
                                  const dds_sample_info_t& info) {
    const int ri = robotIndex(c.team, c.player);
    if (ri < 0) return;
    RobotSlot& s = robots_[static_cast<size_t>(ri)];
    dds_guid_t guid;
    if (!s.stats.owned ||
        !impl_->participantOf(impl_->commands.get(), info.publication_handle, c.team, c.player,
                              guid) ||
        !sameGuid(guid, s.owner)) {
      ++s.stats.refused;
      return;
    }
    // Lockstep: exactly the tick just published. Real time: not newer than
    // it, not older than the last accepted one, at most 1 s old.
    const uint64_t window = ticks_per_second_;
    const bool tick_ok = lockstep
                             ? c.tick == tick
                             : (c.tick <= tick && c.tick >= s.last_tick && c.tick + window >= tick);
    if (!tick_ok) {
      ++s.wrong_tick;
      return;
    }
    // The one check every command goes through (counted there when refused).
    sim::CommandFault fault = sim::CommandFault::None;
    const auto checked =
        sim_.gate().check(static_cast<world::RobotId>(ri),
                          std::span<const float>(c.position._buffer, c.position._length),
                          std::span<const float>(c.stiffness._buffer, c.stiffness._length), &fault);
    if (!checked) {
      if (!s.told_refused && config_.notice) {
        s.told_refused = true;
        config_.notice("team " + std::to_string(s.team) + " player " + std::to_string(s.player) +
                       ": its owner's command refused (" + sim::faultName(fault) + "; " +
                       std::to_string(c.position._length) + " positions of " +
                       std::to_string(world::kActuators) +
                       "); later refusals are counted, not told");
      }
      return;
    }
    s.command = *checked;
    s.has_command = true;
    s.last_tick = c.tick;
  });
}

void SimServer::relayTeamMessages(uint64_t tick) {
  // Messages go by the tick their sender stamped (the frame it was answering;
  // never later than now), not by when they arrived, and at least one period
  // later: a message written while answering tick t is relayed with tick
  // t + 1, when in lockstep every command of t, written after it, is in. So
  // the load of the machine does not change who hears what when.
  const double period = world_.scenario().physics.control_period;
  const auto delay = std::max<uint64_t>(
      1, static_cast<uint64_t>(std::lround(config_.team_message_delay / period)));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  impl_->team_send.take([&](const simsoccer_msg_TeamMessage& m, const dds_sample_info_t& info) {
    const int ri = robotIndex(m.team, m.from_player);
    if (ri < 0) return;
    RobotSlot& sender = robots_[static_cast<size_t>(ri)];
    dds_guid_t guid;
    if (!sender.stats.owned ||
        !impl_->participantOf(impl_->team_send.get(), info.publication_handle, m.team,
                              m.from_player, guid) ||
        !sameGuid(guid, sender.owner) || m.data._length > 128) {
      ++sender.stats.refused;
      return;
    }
    const uint64_t sent = std::min<uint64_t>(m.tick, tick);
    Impl::Pending p{sent + delay, m, {}};
    std::memcpy(p.data.data(), m.data._buffer, m.data._length);
    p.msg.tick = sent;
    // Kept in order of delivery tick, team and sender (one sender's in the
    // order it wrote them): the count and the loss draws do not depend on
    // which sender's message arrived first.
    auto& pending = impl_->pending;
    const auto key = [](const Impl::Pending& x) {
      return std::tie(x.due, x.msg.team, x.msg.from_player);
    };
    pending.insert(std::upper_bound(pending.begin(), pending.end(), p,
                                    [&](const Impl::Pending& a, const Impl::Pending& b) {
                                      return key(a) < key(b);
                                    }),
                   p);
  });
  auto& pending = impl_->pending;
  const auto due_end = std::partition_point(pending.begin(), pending.end(),
                                            [&](const Impl::Pending& p) { return p.due <= tick; });
  for (auto it = pending.begin(); it != due_end; ++it) {
    simsoccer_msg_TeamMessage msg = it->msg;
    msg.data._buffer = it->data.data();
    msg.data._release = false;
    ++team_messages_[msg.team == 0 ? 0 : 1];
    for (size_t k = 0; k < robots_.size(); ++k) {
      const RobotSlot& to = robots_[k];
      if (to.team != msg.team || to.player == msg.from_player) continue;
      if (config_.team_message_loss > 0.0 && unit(impl_->loss_rng) < config_.team_message_loss)
        continue;
      msg.to_player = static_cast<uint8_t>(to.player);
      impl_->robot_writers[k]->team_deliver.write(msg);
    }
  }
  pending.erase(pending.begin(), due_end);
}

void SimServer::poll(double wait_seconds) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(wait_seconds));
  do {
    {
      std::lock_guard lock(mutex_);
      handleJoins();
      checkOwners();
      handleCommands();  // commands before any frame: refused or rejected
    }
    const auto left = std::max(0.0, seconds(Clock::now(), end));
    dds_waitset_wait(impl_->waitset.get(), nullptr, 0, static_cast<dds_duration_t>(left * 1e9));
  } while (Clock::now() < end);
}

bool SimServer::waitForOwners(size_t count, double timeout_seconds) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(timeout_seconds));
  // Owned, and every path between the simulator and the agents matched:
  // a frame or team message sent before its reader is matched is
  // lost, and an agent that misses the first ones plays another game (the
  // same seed would no longer give the same match under load).
  const auto writer_matched = [](dds_entity_t writer, uint32_t n) {
    dds_publication_matched_status_t st{};
    return dds_get_publication_matched_status(writer, &st) == DDS_RETCODE_OK &&
           st.current_count >= n;
  };
  const auto reader_matched = [](dds_entity_t reader, uint32_t n) {
    dds_subscription_matched_status_t st{};
    return dds_get_subscription_matched_status(reader, &st) == DDS_RETCODE_OK &&
           st.current_count >= n;
  };
  auto ready = [&] {
    std::lock_guard lock(mutex_);
    uint32_t owned = 0;
    for (size_t r = 0; r < robots_.size(); ++r) {
      if (!robots_[r].stats.owned) continue;
      ++owned;
      if (!writer_matched(impl_->robot_writers[r]->frame.get(), 1) ||
          !writer_matched(impl_->robot_writers[r]->team_deliver.get(), 1))
        return false;
    }
    return owned >= count && reader_matched(impl_->commands.get(), owned) &&
           reader_matched(impl_->team_send.get(), owned);
  };
  while (!ready() && Clock::now() < end) poll(0.02);
  return ready();
}

void SimServer::observe(const sim::Observation& o) {
  const uint64_t tick = o.tick;
  {
    std::lock_guard lock(mutex_);
    handleJoins();
    checkOwners();
    if (config_.lockstep) {
      // Only answers to this tick's frames count. (In real time a command that
      // came in since the last period is the latest one: it stays.)
      for (RobotSlot& s : robots_) s.has_command = false;
      expected_tick_ = tick;  // from now on commands for `tick` count
    }
    published_tick_ = tick;
  }
  // The game state first (when it changed), then the frames for this tick
  // (the state the commands will answer), each with the robot's perception:
  // one sample per robot and period, so an agent wakes once. (A frame
  // carries the tick and time of the period it closed: this one's.)
  impl_->framesOut();  // the last period's are out (before this period's game state)
  if (o.game) publishGameState(*o.game, o.left_team);
  const size_t n = world_.robotCount();
  impl_->frames_out.resize(n);
  impl_->perceived.resize(n);
  for (world::RobotId r = 0; r < n; ++r) {
    simsoccer_msg_SensorFrame& m = impl_->frames_out[r];
    toMessage(world_.sensorFrame(r), robots_[r].team, robots_[r].player, m);
    if (o.perception) toMessage(o.perception->perception(r), m.perception, impl_->perceived[r]);
  }
  impl_->clock_out = {tick, world_.time(), static_cast<uint8_t>(config_.lockstep)};
  // When the step does not wait for the answers (pipelined), it need not
  // wait for the frames to go out either.
  if (o.actuation_delay > 0)
    impl_->sendInBackground();
  else
    impl_->writeFrames();
  if (impl_->game_state_set && world_.time() - impl_->game_state_published_at >= 0.5 - 1e-9)
    setGameState(impl_->game_state);
  if (impl_->truth) publishTruth(tick);
}

void SimServer::publishTruth(uint64_t tick) {
  simsoccer_msg_WorldTruth t{};
  t.tick = tick;
  t.sim_time = world_.time();
  const auto ball = world_.ballState();
  for (int k = 0; k < 3; ++k) {
    t.ball_position[k] = static_cast<float>(ball.pose.translation()[k]);
    t.ball_velocity[k] = static_cast<float>(ball.linear_velocity[k]);
  }
  std::vector<simsoccer_msg_RobotTruth>& rt = impl_->truth_robots;
  rt.resize(world_.robotCount());
  for (world::RobotId r = 0; r < world_.robotCount(); ++r) {
    const auto pose = world_.torsoPose(r);
    const Eigen::Quaterniond q(pose.linear());
    rt[r].team = static_cast<uint8_t>(robots_[r].team);
    rt[r].player = static_cast<uint8_t>(robots_[r].player);
    for (int k = 0; k < 3; ++k) rt[r].position[k] = static_cast<float>(pose.translation()[k]);
    rt[r].orientation[0] = static_cast<float>(q.x());
    rt[r].orientation[1] = static_cast<float>(q.y());
    rt[r].orientation[2] = static_cast<float>(q.z());
    rt[r].orientation[3] = static_cast<float>(q.w());
  }
  t.robots._buffer = rt.data();
  t.robots._length = static_cast<uint32_t>(rt.size());
  t.robots._maximum = static_cast<uint32_t>(rt.size());
  t.robots._release = false;
  impl_->truth->write(t);
}

void SimServer::collect(uint64_t tick, sim::CommandGate&, std::span<sim::CommandSlot> slots) {
  std::unique_lock lock(mutex_);
  if (config_.lockstep) {
    const auto deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(config_.command_timeout));
    handleCommands();  // anything the listener has not taken yet
    answered_.wait_until(lock, deadline, [&] { return allOwnedAnswered(); });
    expected_tick_ = UINT64_MAX;  // late answers are stale from here on
  } else {
    handleCommands();
  }
  relayTeamMessages(tick);
  for (size_t r = 0; r < robots_.size() && r < slots.size(); ++r) {
    RobotSlot& s = robots_[r];
    if (s.has_command) {
      slots[r] = {sim::Answer::Given, s.command};
      if (!config_.lockstep) s.has_command = false;  // applied once
    } else if (s.stats.owned && config_.lockstep) {
      slots[r].answer = sim::Answer::Missed;  // keeps its last command
    }
  }
}

void SimServer::afterStep(const world::World&) {
  // Status at 1 Hz of simulated time (and at every ownership change).
  if (published_tick_ % ticks_per_second_ != 0) return;
  std::lock_guard lock(mutex_);
  for (world::RobotId r = 0; r < world_.robotCount(); ++r) publishStatus(r);
}

}  // namespace simsoccer::net
