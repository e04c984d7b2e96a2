#include "simsoccer/booster/endpoint.hpp"

#include <fcntl.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <deque>
#include <exception>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

#include "booster_sdk.h"
#include "simsoccer/agents/behaviour/kick_approach.hpp"
#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/net/dds.hpp"

namespace simsoccer::booster {

using Clock = std::chrono::steady_clock;
using LowState = booster_interface_msg_dds__LowState_;
using LowCmd = booster_interface_msg_dds__LowCmd_;
using MotorState = booster_interface_msg_dds__MotorState_;
using FallDown = booster_interface_msg_dds__FallDownState_;
using RpcReq = booster_msgs_msg_dds__RpcReqMsg_;
using RpcResp = booster_msgs_msg_dds__RpcRespMsg_;
using Image = sensor_msgs_msg_dds__Image_;
using CompressedImage = sensor_msgs_msg_dds__CompressedImage_;
using KickTarget = brain_msg_dds__Kick_;
using Odometer = booster_interface_msg_dds__Odometer_;
using HeadPose = geometry_msgs_msg_dds__Pose_;

namespace {
net::QosSpec qos(bool reliable, int depth, bool transient_local = false) {
  net::QosSpec q;
  q.reliable = reliable;
  q.depth = depth;
  q.transient_local = transient_local;
  return q;
}
}  // namespace

struct Endpoint::Robot {
  BoosterRobot config;
  size_t actuators = 0;
  net::Participant participant;
  net::Writer<LowState> state;
  net::Reader<LowCmd> commands;
  net::Reader<RpcReq> requests;
  net::Writer<RpcResp> answers;
  net::Writer<FallDown> fall;
  net::Reader<KickTarget> kick_targets;
  net::Writer<Odometer> odometer;
  net::Writer<HeadPose> head_pose;
  LocoService loco;
  // The odometry's origin (the trunk's planar pose at the start or the last ResetOdometry).
  std::optional<world::Pose> odometry_origin;
  uint64_t odometry_resets = 0;
  int head_link = -1;  // the model's link "Head", if it has one
  RobotBoosterStats stats;
  // Camera images (attachCameras), written from the camera conversion thread.
  std::unique_ptr<net::Writer<Image>> image;
  std::unique_ptr<net::Writer<CompressedImage>> compressed;
  std::atomic<uint64_t> images{0};

  // The well-formed LowCmds (SERIAL, one entry per actuator) taken and not
  // yet applied, oldest first; the last that passes the gate drives.
  struct Command {
    std::vector<float> q, dq, tau, kp, kd;
  };
  static constexpr size_t kMaxPending = 16;  // the reader's depth
  std::vector<Command> pending_pool;
  size_t pending = 0;
  bool ever_commanded = false;  // lockstep waits only for a client that commands
  // Lockstep: a client that missed `unresponsive_after` periods in a row is
  // no longer waited for until it answers again.
  int missed_in_row = 0;
  bool unresponsive = false;
  dds_entity_t command_condition = 0;          // data on rt/joint_ctrl (owned by the reader)
  const std::vector<double>* stand = nullptr;  // the model's stand pose
  // Walking and Soccer: simsoccer's walk (the built-in agents' motion layer),
  // loaded with the endpoint and restarted from the measured joints on each entry.
  std::unique_ptr<agents::MotionController> motion;
  bool was_walking = false;
  // The walk's targets, each with the period it acts from (walkTargets), oldest first.
  struct WalkTargets {
    uint64_t acts_at = 0;
    std::array<float, world::kActuators> position{}, stiffness{};
  };
  std::deque<WalkTargets> walk_targets;
  // Shoot and VisualKick: the kick approach (the motions folder's
  // kick_approach.yaml), the ball as the robot's perception saw it last, the
  // latest rt/kick_ball direction (rad, robot frame when the heading was
  // target_yaw, at simulation time target_at).
  std::unique_ptr<agents::KickApproach> approach;
  agents::BallSighting ball;
  uint64_t visual_kick_start = 0;  // the service's VisualKick start the kick approach runs for
  bool shooting = false;
  int kicks_before_shot = 0;  // the walk's kicks when the Shoot was taken
  agents::Leg shoot_foot = agents::Leg::Right;
  double shoot_until = -1.0;
  std::optional<double> target_dir;
  double target_yaw = 0.0, target_at = -1e9;

  // LowState buffers (the sample points at them) and the last joint speeds.
  std::vector<MotorState> motors;
  std::vector<float> last_dq;
  bool has_last = false;
  int fall_state = -1;
  double fall_sent_at = -1e9;

  Robot(const BoosterRobot& c, size_t n, const net::DomainConfig& dds, LocoCapabilities can)
      : config(c),
        actuators(n),
        participant(dds),
        state(participant, booster_interface_msg_dds__LowState__desc, "rt/low_state", qos(true, 5)),
        // Best effort matches both reliable and best-effort writers; 16 deep so
        // that every command of a period is seen (the last good one drives).
        commands(participant, booster_interface_msg_dds__LowCmd__desc, "rt/joint_ctrl",
                 qos(false, 16)),
        requests(participant, booster_msgs_msg_dds__RpcReqMsg__desc, "rt/LocoApiTopicReq",
                 qos(true, 10)),
        answers(participant, booster_msgs_msg_dds__RpcRespMsg__desc, "rt/LocoApiTopicResp",
                qos(true, 10, true)),
        fall(participant, booster_interface_msg_dds__FallDownState__desc, "rt/fall_down",
             qos(true, 1)),
        // Best effort, as Booster's own readers of it: matches every writer.
        kick_targets(participant, brain_msg_dds__Kick__desc, "rt/kick_ball", qos(false, 4)),
        // Reliable: matches the SDK's best-effort readers and ROS 2's reliable default ones
        // (Booster's soccer demo subscribes with depth 1, reliable).
        odometer(participant, booster_interface_msg_dds__Odometer__desc, "rt/odometer_state",
                 qos(true, 1)),
        head_pose(participant, geometry_msgs_msg_dds__Pose__desc, "rt/head_pose", qos(true, 1)),
        loco(c.initial_mode, can),
        pending_pool(kMaxPending,
                     Command{std::vector<float>(n), std::vector<float>(n), std::vector<float>(n),
                             std::vector<float>(n), std::vector<float>(n)}),
        motors(n),
        last_dq(n) {
    command_condition = dds_create_readcondition(commands.get(), DDS_ANY_STATE);
    if (command_condition < 0) net::check(command_condition, "create read condition");
  }
};

Endpoint::Endpoint(const world::World& world, EndpointConfig config)
    : world_(world), config_(std::move(config)) {
  if (!(config_.answer_timeout > 0.0 && config_.answer_timeout <= 60.0))
    throw std::invalid_argument("Booster endpoint: answer timeout must be in (0, 60] s");
  const double period = world.scenario().physics.control_period;
  walk_periods_ = static_cast<uint64_t>(std::max(1L, std::lround(kWalkPeriod / period)));
  walk_dt_ = static_cast<double>(walk_periods_) * period;
  std::set<world::RobotId> robots;
  std::set<uint32_t> domains;
  for (const BoosterRobot& b : config_.robots) {
    if (b.robot >= world.robotCount())
      throw std::invalid_argument("Booster endpoint: no robot " + std::to_string(b.robot));
    if (!robots.insert(b.robot).second)
      throw std::invalid_argument("Booster endpoint: robot " + std::to_string(b.robot) +
                                  " is served twice");
    if (!domains.insert(b.domain).second)
      throw std::invalid_argument("Booster endpoint: two robots on DDS domain " +
                                  std::to_string(b.domain) +
                                  " (the SDK's topics carry no robot id: one robot per domain)");
    if (b.domain > 230)
      throw std::invalid_argument("Booster endpoint: DDS domain " + std::to_string(b.domain) +
                                  " is beyond 230 (the RTPS port mapping)");
    const robots::RobotModel& model = *world.robot(b.robot).model;
    const std::vector<double>& stand = model.pose("stand");  // throws if the model has none
    const bool walk = !b.motions.empty();
    const std::filesystem::path approach = b.motions / "kick_approach.yaml";
    const LocoCapabilities can{walk, walk && std::filesystem::exists(approach),
                               world.scenario().perception.enabled};
    net::DomainConfig dds;
    dds.domain = b.domain;
    dds.config_file = config_.dds_config;
    std::unique_ptr<Robot> r;
    if (b.network_namespace.empty()) {
      r = std::make_unique<Robot>(b, model.actuators.size(), dds, can);
    } else {
      // Cyclone opens the domain's sockets and starts its threads when the
      // domain is made: made on a thread inside the namespace, they stay
      // there (a thread's network namespace is its own; this one ends after).
      dds.external_domain = b.namespace_domain;
      std::exception_ptr failed;
      std::thread([&] {
        try {
          const std::string path = "/run/netns/" + b.network_namespace;
          const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
          if (fd < 0) throw std::invalid_argument("Booster endpoint: no network namespace " + path);
          const int rc = ::setns(fd, CLONE_NEWNET);
          ::close(fd);
          if (rc != 0)
            throw std::runtime_error("Booster endpoint: cannot enter network namespace " +
                                     b.network_namespace + " (needs CAP_SYS_ADMIN)");
          r = std::make_unique<Robot>(b, model.actuators.size(), dds, can);
        } catch (...) {
          failed = std::current_exception();
        }
      }).join();
      if (failed) std::rethrow_exception(failed);
    }
    r->stand = &stand;
    r->head_link = model.body->linkIndex("Head");
    // The walk's motions are read here, so a bad motions folder refuses to start (not the
    // first period in WALKING).
    if (walk)
      r->motion = std::make_unique<agents::MotionController>(
          agents::loadMotionController(model, b.motions));
    if (can.kicks)
      r->approach = std::make_unique<agents::KickApproach>(agents::loadKickApproach(approach));
    robots_.push_back(std::move(r));
  }
  // Lockstep waits on every robot's commands at once.
  waitset_ = net::check(dds_create_waitset(DDS_CYCLONEDDS_HANDLE), "create waitset");
  for (auto& r : robots_)
    net::check(dds_waitset_attach(waitset_, r->command_condition, 0), "attach read condition");
}

Endpoint::~Endpoint() {
  if (waitset_ > 0) dds_delete(waitset_);
}

void Endpoint::attachCameras(sim::Simulation& simulation) {
  const world::CameraSettings& cameras = world_.scenario().cameras;
  if (!cameras.enabled)
    throw std::invalid_argument("Booster endpoint: the scenario's cameras are off");
  for (auto& rp : robots_) {
    Robot& r = *rp;
    if (cameras.encoding == "jpeg")
      r.compressed = std::make_unique<net::Writer<CompressedImage>>(
          r.participant, sensor_msgs_msg_dds__CompressedImage__desc,
          config_.image_topic + "/compressed", qos(true, 1));
    else
      r.image = std::make_unique<net::Writer<Image>>(
          r.participant, sensor_msgs_msg_dds__Image__desc, config_.image_topic, qos(true, 1));
  }
  simulation.addImageSink([this](const world::CameraImage& image) { publishImage(image); });
}

void Endpoint::publishImage(const world::CameraImage& image) {
  if (image.camera != world::CameraId::Top) return;  // the robot's first camera
  for (auto& rp : robots_) {
    Robot& r = *rp;
    if (r.config.robot != image.robot) continue;
    // The simulation time, as the robot's clock would stamp it.
    const long long ns = std::llround(image.sim_time * 1e9);
    const std::string frame = "camera";
    std_msgs_msg_dds__Header_ header{};
    header.stamp.sec = static_cast<int32_t>(ns / 1000000000LL);
    header.stamp.nanosec = static_cast<uint32_t>(ns % 1000000000LL);
    header.frame_id = const_cast<char*>(frame.c_str());
    if (r.image && image.encoding == world::ImageEncoding::Yuyv) {
      const std::string encoding = "yuv422_yuy2";
      Image m{};
      m.header = header;
      m.width = static_cast<uint32_t>(image.view.width);
      m.height = static_cast<uint32_t>(image.view.height);
      m.encoding = const_cast<char*>(encoding.c_str());
      m.step = m.width * 2;
      m.data._buffer = const_cast<uint8_t*>(image.data.data());
      m.data._length = m.data._maximum = static_cast<uint32_t>(image.data.size());
      m.data._release = false;
      r.image->write(m);
      ++r.images;
    } else if (r.compressed && image.encoding == world::ImageEncoding::Jpeg) {
      const std::string format = "jpeg";
      CompressedImage m{};
      m.header = header;
      m.format = const_cast<char*>(format.c_str());
      m.data._buffer = const_cast<uint8_t*>(image.data.data());
      m.data._length = m.data._maximum = static_cast<uint32_t>(image.data.size());
      m.data._release = false;
      r.compressed->write(m);
      ++r.images;
    }
  }
}

RobotBoosterStats Endpoint::stats(std::size_t i) const {
  const Robot& r = *robots_.at(i);
  RobotBoosterStats s = r.stats;
  s.images = r.images.load();
  s.mode = r.loco.mode();
  s.requests = r.loco.requests();
  s.requests_refused = r.loco.refused();
  s.requests_malformed = r.loco.malformed();
  if (r.motion) {
    const agents::MotionCounters& c = r.motion->counters();
    s.kicks = static_cast<uint64_t>(c.kicks);
    s.falls = static_cast<uint64_t>(c.falls);
    s.get_ups = static_cast<uint64_t>(c.get_ups);
  }
  return s;
}

bool Endpoint::clientConnected(std::size_t i) const {
  dds_publication_matched_status_t st{};
  if (dds_get_publication_matched_status(robots_.at(i)->state.get(), &st) != DDS_RETCODE_OK)
    return false;
  return st.current_count > 0;
}

namespace {

// Takes every LowCmd that arrived: a malformed one is refused and counted,
// a well-formed one joins the pending (the oldest goes beyond kMaxPending).
void takeCommands(auto& r) {
  r.commands.take([&](const LowCmd& c, const dds_sample_info_t&) {
    ++r.stats.commands;
    r.ever_commanded = true;
    if (c.cmd_type != booster_interface_msg_dds__SERIAL || c.motor_cmd._length != r.actuators) {
      // PARALLEL needs the ankle linkage, which the model does not have.
      ++r.stats.refused;
      return;
    }
    if (r.pending == r.pending_pool.size()) {
      std::rotate(r.pending_pool.begin(), r.pending_pool.begin() + 1, r.pending_pool.end());
      --r.pending;
    }
    auto& p = r.pending_pool[r.pending++];
    for (size_t a = 0; a < r.actuators; ++a) {
      const auto& m = c.motor_cmd._buffer[a];
      p.q[a] = m.q;
      p.dq[a] = m.dq;
      p.tau[a] = m.tau;
      p.kp[a] = m.kp;
      p.kd[a] = m.kd;
    }
  });
}

}  // namespace

void Endpoint::observe(const sim::Observation& o) {
  const world::World& w = *o.world;
  const double period = w.scenario().physics.control_period;
  time_ = o.time;
  acts_at_ = o.tick + static_cast<uint64_t>(std::max(0, o.actuation_delay));
  for (auto& rp : robots_) {
    Robot& r = *rp;
    // The ball as the robot's cameras saw it (the simulation's perception):
    // what its kicks go for.
    if (o.perception && r.approach) {
      const world::PerceivedObject& b = o.perception->perception(r.config.robot).ball;
      r.ball = agents::BallSighting{b.x, b.y, b.last_seen < 0.0 ? -1.0 : o.time - b.last_seen};
    }
    // Lockstep: what came after the last period's wait answers a state that
    // is gone; it must not answer the new one (the robot would run a period
    // behind for good).
    if (config_.lockstep) {
      takeCommands(r);
      r.stats.late += r.pending;
      r.pending = 0;
    }
    const world::SensorFrame& f = w.sensorFrame(r.config.robot);
    const auto& info = w.robot(r.config.robot);
    const auto& actuators = info.model->actuators;
    for (size_t a = 0; a < r.actuators; ++a) {
      MotorState& m = r.motors[a];
      m = MotorState{};
      m.q = f.position[a];
      m.dq = f.velocity[a];
      m.ddq = r.has_last ? static_cast<float>((f.velocity[a] - r.last_dq[a]) / period) : 0.0f;
      r.last_dq[a] = f.velocity[a];
      if (actuators[a].kind == robots::Actuator::Kind::Joint)
        m.tau_est = static_cast<float>(w.physics().jointMotorTorque(info.body, actuators[a].index));
      m.temperature = static_cast<uint8_t>(std::clamp(std::lround(f.temperature[a]), 0L, 255L));
    }
    r.has_last = true;
    LowState s{};
    for (int k = 0; k < 3; ++k) {
      s.imu_state.rpy[k] = f.angles[static_cast<size_t>(k)];
      s.imu_state.gyro[k] = f.gyroscope[static_cast<size_t>(k)];
      s.imu_state.acc[k] = f.accelerometer[static_cast<size_t>(k)];
    }
    // Joint space; the motor space is the same until the ankle linkage is
    // modelled (the cranks are reported as the serial ankle joints).
    for (auto* seq : {&s.motor_state_serial, &s.motor_state_parallel}) {
      seq->_buffer = r.motors.data();
      seq->_length = seq->_maximum = static_cast<uint32_t>(r.actuators);
      seq->_release = false;
    }
    r.state.write(s);
    ++r.stats.states_sent;
    publishPoses(r, w);

    // The walk runs at its own period, on the state of its period's start.
    if (r.loco.walking()) {
      if (o.tick % walk_periods_ == 0) walkTargets(r, f, o.tick + walk_periods_);
    } else {
      // Out of walking (any other mode, CUSTOM included), the walk starts over on its next use.
      r.was_walking = r.shooting = false;
      r.walk_targets.clear();
    }
    int fallen = w.isStanding(r.config.robot) ? booster_interface_msg_dds__IS_READY
                                              : booster_interface_msg_dds__HAS_FALLEN;
    // Walking and Soccer: the walk's fall detector and get-up tell the phases between (the
    // SDK's IS_FALLING and IS_GETTING_UP), as the robot's own recovery does (read after this
    // period's walk update).
    if (r.motion && r.loco.walking() && r.was_walking) {
      switch (r.motion->state()) {
        case agents::MotionState::Falling:
          fallen = booster_interface_msg_dds__IS_FALLING;
          break;
        case agents::MotionState::Lying:
          fallen = booster_interface_msg_dds__HAS_FALLEN;
          break;
        case agents::MotionState::GettingUp:
          fallen = booster_interface_msg_dds__IS_GETTING_UP;
          break;
        default:
          break;
      }
    }
    if (fallen != r.fall_state || o.time - r.fall_sent_at >= config_.fall_down_interval) {
      FallDown fd{};
      fd.fall_down_state = static_cast<booster_interface_msg_dds__FallDownStateType>(fallen);
      // Walking and Soccer get up (the walk's fall detector); other modes do not.
      fd.is_recovery_available = r.loco.walking();
      r.fall.write(fd);
      r.fall_state = fallen;
      r.fall_sent_at = o.time;
    }
  }
}

void Endpoint::publishPoses(Robot& r, const world::World& w) {
  // The robot's base frame: on the ground under the trunk, x along the trunk's heading, z up.
  // It is the odometry's frame (its pose since the origin; ground truth, where a real K1's
  // odometry comes from its gait and drifts) and the head pose's (Booster's demo intersects
  // camera rays with its z = 0 plane).
  const world::Pose trunk = w.torsoPose(r.config.robot);
  world::Pose base = world::Pose::Identity();
  base.translation() = Eigen::Vector3d(trunk.translation().x(), trunk.translation().y(), 0.0);
  base.linear() = Eigen::AngleAxisd(std::atan2(trunk.linear()(1, 0), trunk.linear()(0, 0)),
                                    Eigen::Vector3d::UnitZ())
                      .toRotationMatrix();
  if (!r.odometry_origin || r.loco.odometryResets() != r.odometry_resets) {
    r.odometry_origin = base;
    r.odometry_resets = r.loco.odometryResets();
  }
  const world::Pose moved = r.odometry_origin->inverse() * base;
  Odometer odo{};
  odo.x = static_cast<float>(moved.translation().x());
  odo.y = static_cast<float>(moved.translation().y());
  odo.theta = static_cast<float>(std::atan2(moved.linear()(1, 0), moved.linear()(0, 0)));
  r.odometer.write(odo);
  if (r.head_link < 0) return;
  const world::Pose head = base.inverse() * w.linkPose(r.config.robot, r.head_link);
  const Eigen::Quaterniond q(head.linear());
  HeadPose p{};
  p.position.x = head.translation().x();
  p.position.y = head.translation().y();
  p.position.z = head.translation().z();
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  p.orientation.w = q.w();
  r.head_pose.write(p);
}

void Endpoint::walkTargets(Robot& r, const world::SensorFrame& frame, uint64_t acts_at) {
  // Walking and Soccer: simsoccer's walk at Move's velocity, the head
  // where RotateHead turned it; from standing still it eases into the
  // walk's stance (and after a fall it gets up). Every kWalkPeriod on the
  // state of that moment, its targets acting one walk period later: the
  // built-in agents' timing in matches, which the K1's walk and kick were
  // tuned with (without the delay, or at 2 ms periods with 2 ms of it, the K1
  // fell after its kicks).
  if (!r.was_walking) {
    r.motion->restart();
    ++r.stats.walk_starts;
  }
  r.was_walking = true;
  const double yaw = frame.angles[2];
  agents::MotionRequest request;
  const bool visual = r.approach && r.loco.visualKick();
  if (visual) {
    // The visual kick: to the ball the robot sees, kicked the way
    // rt/kick_ball says (a direction sent with the start holds).
    r.shooting = false;
    if (r.visual_kick_start != r.loco.visualKickStarts()) {
      r.visual_kick_start = r.loco.visualKickStarts();
      r.approach->start(time_, yaw);
      if (r.target_dir && time_ - r.target_at < 1.0) r.approach->aimAt(*r.target_dir, r.target_yaw);
    }
    request = r.approach->update(time_, r.ball, yaw, r.motion->state(),
                                 r.motion->feetCentre(agents::motionSensors(frame)));
  } else {
    if (r.loco.takeShoot()) {
      // Shoot: one kick where it stands, with the foot on the side of a
      // ball it saw near in the last second (else the right).
      r.shooting = true;
      r.kicks_before_shot = r.motion->counters().kicks;
      r.shoot_until = time_ + 3.0;
      const bool near =
          r.ball.age >= 0.0 && r.ball.age < 1.0 && std::hypot(r.ball.x, r.ball.y) < 1.0;
      const double beside = r.ball.y - r.motion->feetCentre(agents::motionSensors(frame)).y();
      r.shoot_foot = near && beside >= 0.0 ? agents::Leg::Left : agents::Leg::Right;
    }
    // Asked for until the motion layer kicks (it stops the walk first), 3 s at most (it may be
    // getting up: the shot is dropped).
    if (r.motion->counters().kicks > r.kicks_before_shot || time_ > r.shoot_until)
      r.shooting = false;
    const WalkVelocity& v = r.loco.velocity();
    if (r.shooting) {
      request.kind = agents::MotionRequest::Kind::Kick;
      request.kick_foot = r.shoot_foot;
    } else if (v.vx != 0.0 || v.vy != 0.0 || v.vyaw != 0.0) {
      request.kind = agents::MotionRequest::Kind::Walk;
      request.forward = v.vx;
      request.left = v.vy;
      request.turn = v.vyaw;
    }
    if (const auto& head = r.loco.headTarget()) {
      request.head_yaw = head->yaw;
      request.head_pitch = head->pitch;
    }
  }
  Robot::WalkTargets& t = r.walk_targets.emplace_back();
  t.acts_at = acts_at;
  r.motion->update(walk_dt_, agents::motionSensors(frame), request, t.position, t.stiffness);
  // Kicks need the robot on its feet (the walk's fall detector tells).
  const agents::MotionState m = r.motion->state();
  r.loco.setDown(m == agents::MotionState::Falling || m == agents::MotionState::Lying ||
                 m == agents::MotionState::GettingUp);
}

void Endpoint::answerRequests(Robot& r) {
  r.requests.take([&](const RpcReq& req, const dds_sample_info_t&) {
    const RpcAnswer a = r.loco.handle(req.header ? req.header : "", req.body ? req.body : "");
    if (!a.respond) return;
    const std::string header = nlohmann::json{{"status", a.status}}.dump();
    RpcResp resp{};
    resp.uuid = req.uuid ? req.uuid : const_cast<char*>("");
    resp.header = const_cast<char*>(header.c_str());
    resp.body = const_cast<char*>(a.body.c_str());
    r.answers.write(resp);
  });
}

void Endpoint::takeKickTargets(Robot& r) {
  const double yaw = world_.sensorFrame(r.config.robot).angles[2];
  r.kick_targets.take([&](const KickTarget& k, const dds_sample_info_t&) {
    ++r.stats.kick_targets;
    if (!std::isfinite(k.dir) || std::abs(k.dir) > 2 * std::numbers::pi) {  // not an angle
      ++r.stats.kick_targets_refused;
      return;
    }
    r.target_dir = k.dir;
    r.target_yaw = yaw;
    r.target_at = time_;
    if (r.approach && r.loco.visualKick() && r.visual_kick_start == r.loco.visualKickStarts())
      r.approach->aimAt(k.dir, yaw);
  });
}

void Endpoint::collect(uint64_t, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) {
  for (auto& rp : robots_) {
    Robot& r = *rp;
    answerRequests(r);
    takeKickTargets(r);
    takeCommands(r);
  }
  const auto awaited = [&](const Robot& r) {
    return config_.lockstep && r.loco.mode() == RobotMode::Custom && r.ever_commanded &&
           !r.unresponsive && r.pending == 0;
  };
  if (config_.lockstep) {
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(config_.answer_timeout));
    for (;;) {
      bool waiting = false;
      for (auto& rp : robots_) waiting = waiting || awaited(*rp);
      const auto left =
          std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - Clock::now());
      if (!waiting || left.count() <= 0) break;
      dds_waitset_wait(waitset_, nullptr, 0, static_cast<dds_duration_t>(left.count()));
      for (auto& rp : robots_) takeCommands(*rp);
    }
  }

  for (auto& rp : robots_) {
    Robot& r = *rp;
    sim::CommandSlot& slot = slots[r.config.robot];
    if (r.loco.mode() != RobotMode::Custom) {
      r.stats.ignored += r.pending;
      r.pending = 0;
      r.missed_in_row = 0;
      // The mode's command, every period: whatever moved the servos since (a
      // referee placing the robot holds its joints) does not last.
      if (const auto command = modeCommand(r, gate)) {
        slot.answer = sim::Answer::Given;
        slot.command = *command;
      }
      continue;
    }
    if (r.pending == 0) {
      if (config_.lockstep && r.ever_commanded && !r.unresponsive) {
        ++r.stats.missed;
        slot.answer = sim::Answer::Missed;
        if (++r.missed_in_row >= config_.unresponsive_after) r.unresponsive = true;
      }
      continue;  // holds its last command, as the robot does
    }
    r.missed_in_row = 0;
    r.unresponsive = false;
    // The last command of the period that passes the gate drives.
    std::optional<sim::RobotCommand> good;
    for (size_t k = 0; k < r.pending; ++k) {
      const auto& p = r.pending_pool[k];
      auto command = gate.checkServo(r.config.robot, {p.q, p.dq, p.tau, p.kp, p.kd});
      if (command)
        good = std::move(command);
      else
        ++r.stats.refused;
    }
    r.pending = 0;
    if (!good) continue;
    ++r.stats.applied;
    slot.answer = sim::Answer::Given;
    slot.command = *good;
  }
}

std::optional<sim::RobotCommand> Endpoint::modeCommand(Robot& r, sim::CommandGate& gate) const {
  const robots::RobotModel& model = *world_.robot(r.config.robot).model;
  const size_t n = r.actuators;
  if (r.loco.walking()) {
    // Walking and Soccer: the walk's latest targets due by the period this command acts in
    // (none yet: the robot holds its last command).
    auto& q = r.walk_targets;
    while (q.size() > 1 && q[1].acts_at <= acts_at_) q.pop_front();
    if (q.empty() || q.front().acts_at > acts_at_) return std::nullopt;
    return gate.check(r.config.robot, std::span<const float>(q.front().position),
                      std::span<const float>(q.front().stiffness));
  }
  if (r.loco.mode() == RobotMode::Prepare) {
    // Standing: the stand pose on the robot's own servos, the head where
    // RotateHead turned it (clamped to the joints' limits).
    std::array<float, world::kActuators> position{}, stiffness{};
    for (size_t a = 0; a < n; ++a) {
      const auto& act = model.actuators[a];
      if (act.kind != robots::Actuator::Kind::Joint) continue;
      const auto& joint = model.body->joints[static_cast<size_t>(act.index)];
      double target = (*r.stand)[static_cast<size_t>(act.index)];
      if (const auto& head = r.loco.headTarget()) {
        if (act.name == "HeadYaw") target = head->yaw;
        if (act.name == "HeadPitch") target = head->pitch;
      }
      position[a] = static_cast<float>(std::clamp(target, joint.lower, joint.upper));
      stiffness[a] = 1.0f;
    }
    return gate.check(r.config.robot, std::span<const float>(position),
                      std::span<const float>(stiffness));
  }
  // Damping: every joint limp but damped by its motor's kd (kp 0: the
  // position is the joint's own, inside its limits).
  std::array<float, world::kActuators> zero{}, position{}, kd{};
  const world::SensorFrame& f = world_.sensorFrame(r.config.robot);
  for (size_t a = 0; a < n; ++a) {
    const auto& act = model.actuators[a];
    if (act.kind != robots::Actuator::Kind::Joint) continue;
    const auto& joint = model.body->joints[static_cast<size_t>(act.index)];
    position[a] = static_cast<float>(std::clamp<double>(f.position[a], joint.lower, joint.upper));
    kd[a] = static_cast<float>(model.body->motors[static_cast<size_t>(joint.motor)].kd);
  }
  const std::span<const float> z = std::span<const float>(zero).first(n);
  return gate.checkServo(r.config.robot, {std::span<const float>(position).first(n), z, z, z,
                                          std::span<const float>(kd).first(n)});
}

}  // namespace simsoccer::booster
