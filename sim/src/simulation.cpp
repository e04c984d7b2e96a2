#include "simsoccer/sim/simulation.hpp"

#include <algorithm>
#include <stdexcept>

namespace simsoccer::sim {

namespace {
using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

const char* modeName(Mode m) {
  return m == Mode::Serial ? "serial" : "pipelined";
}

Mode parseMode(const std::string& name) {
  if (name == "serial") return Mode::Serial;
  if (name == "pipelined") return Mode::Pipelined;
  throw std::invalid_argument("'" + name + "' is not a period mode (serial or pipelined)");
}

Simulation::Simulation(world::World& world, const SimulationConfig& config)
    : world_(world),
      config_(config),
      gate_(world, config.position_margin),
      due_(world.robotCount()),
      collected_(world.robotCount()),
      observed_placements_(world.robotCount(), 0),
      due_placements_(world.robotCount(), 0),
      applied_(world.robotCount()),
      commanded_(world.robotCount(), false),
      accepted_(world.robotCount(), 0),
      missed_(world.robotCount(), 0) {
  if (world.scenario().perception.enabled)
    perception_ = std::make_unique<world::PerceptionSystem>(world, world.scenario().perception);
}

Simulation::~Simulation() {
  cameras_.reset();  // delivers what is queued while the sinks still exist
}

void Simulation::addSource(CommandSource& source) {
  sources_.push_back(&source);
}

void Simulation::addRecorder(Recorder& recorder) {
  recorders_.push_back(&recorder);
}

void Simulation::addImageSink(std::function<void(const world::CameraImage&)> sink) {
  if (cameras_started_)
    throw std::logic_error("Simulation::addImageSink after the first period");
  image_sinks_.push_back(std::move(sink));
}

void Simulation::setOfficials(Officials* officials) {
  officials_ = officials;
  game_.reset();
  if (officials_) game_ = officials_->controlData();
}

std::optional<referee::ControlData> Simulation::game() const {
  return game_;
}

CommandStats Simulation::commandStats(world::RobotId r) const {
  return {accepted_.at(r), gate_.rejected(r), missed_.at(r)};
}

void Simulation::ensureCameras() {
  if (cameras_started_) return;
  cameras_started_ = true;
  const world::CameraSettings& settings = world_.scenario().cameras;
  if (!settings.enabled) return;
  cameras_ = std::make_unique<world::CameraSystem>(
      world_, settings, config_.lockstep ? world::BehindPolicy::Wait : world::BehindPolicy::Drop,
      [this](const world::CameraImage& image) {
        if (image.camera == world::CameraId::Spectator) {
          if (config_.spectator_sink) config_.spectator_sink(image);
          return;
        }
        for (const auto& sink : image_sinks_) sink(image);
      });
  cameras_->capture(world_);  // the images of the first tick
}

void Simulation::dropPending(world::RobotId r) {
  due_.at(r).answer = Answer::None;
}

void Simulation::flushCameras() {
  if (cameras_) cameras_->flush();
}

void Simulation::observe(uint64_t tick) {
  // Perception first: the sources send it with this tick's frames.
  if (perception_) {
    const auto t0 = Clock::now();
    perception_->update(world_);
    profile_.perception_s += seconds(t0, Clock::now());
  }
  Observation o;
  o.tick = tick;
  o.time = world_.time();
  o.world = &world_;
  o.perception = perception_.get();
  o.actuation_delay = config_.mode == Mode::Pipelined ? 1 : 0;
  for (world::RobotId r = 0; r < world_.robotCount(); ++r)
    observed_placements_[r] = world_.placements(r);
  if (game_) {
    o.game = &*game_;
    o.left_team = officials_->leftTeam();
  }
  for (CommandSource* s : sources_) s->observe(o);
}

void Simulation::collect(uint64_t tick) {
  for (CommandSlot& s : collected_) s.answer = Answer::None;
  for (CommandSource* s : sources_) s->collect(tick, gate_, collected_);
  std::swap(collected_, due_);  // the answers the next apply() takes
  due_placements_ = observed_placements_;
}

void Simulation::apply() {
  for (world::RobotId r = 0; r < world_.robotCount(); ++r) {
    commanded_[r] = false;
    const CommandSlot& s = due_[r];
    if (s.answer == Answer::Missed) ++missed_[r];
    if (s.answer != Answer::Given) continue;
    if (world_.placements(r) != due_placements_[r]) continue;  // answers a robot since moved
    // The command holds kActuators slots; the robot uses its own count of them.
    const size_t n = world_.robot(r).model->actuators.size();
    const RobotCommand& c = s.command;
    if (c.with_gains)
      world_.setServoCommand(r, {std::span<const double>(c.position).first(n),
                                 std::span<const double>(c.velocity).first(n),
                                 std::span<const double>(c.torque).first(n),
                                 std::span<const double>(c.kp).first(n),
                                 std::span<const double>(c.kd).first(n)});
    else
      world_.setCommand(r, std::span<const double>(c.position).first(n),
                        std::span<const double>(c.stiffness).first(n));
    applied_[r] = s.command;
    commanded_[r] = true;
    ++accepted_[r];
  }
}

void Simulation::period() {
  ensureCameras();
  const uint64_t tick = world_.controlTick();
  const auto t0 = Clock::now();
  observe(tick);
  const auto t1 = Clock::now();
  auto t2 = t1;
  if (config_.mode == Mode::Serial) {
    collect(tick);
    t2 = Clock::now();
  }
  apply();
  const auto t3 = Clock::now();
  world_.stepControlPeriod();
  const auto t4 = Clock::now();
  auto t5 = t4;
  if (config_.mode == Mode::Pipelined) {
    // The drivers computed their answers to `tick` while the world stepped;
    // they act in the next period.
    collect(tick);
    t5 = Clock::now();
  }
  for (CommandSource* s : sources_) s->afterStep(world_);
  events_.clear();
  if (officials_) {
    for (int team = 0; team < 2; ++team) {
      uint64_t sent = 0;
      for (const CommandSource* s : sources_) sent += s->teamMessagesSent(team);
      officials_->teamMessages(team, sent);
    }
    officials_->afterStep(events_);
    game_ = officials_->controlData();
  }
  const auto t6 = Clock::now();
  if (!recorders_.empty()) {
    PeriodRecord p;
    p.tick = tick;
    p.world = &world_;
    p.commands = &applied_;
    p.commanded = &commanded_;
    p.events = &events_;
    p.game = game_ ? &*game_ : nullptr;
    for (Recorder* r : recorders_) r->record(p);
  }
  const auto t7 = Clock::now();
  if (cameras_) cameras_->capture(world_);  // the state the next frames describe
  const auto t8 = Clock::now();
  profile_.observe_s += seconds(t0, t1);
  profile_.collect_s += seconds(t1, t2) + seconds(t4, t5);
  profile_.longest_collect_s =
      std::max(profile_.longest_collect_s, seconds(t1, t2) + seconds(t4, t5));
  profile_.apply_s += seconds(t2, t3);
  profile_.step_s += seconds(t3, t4);
  profile_.officials_s += seconds(t5, t6);
  profile_.record_s += seconds(t6, t7);
  profile_.camera_s += seconds(t7, t8);
  ++profile_.periods;
}

}  // namespace simsoccer::sim
