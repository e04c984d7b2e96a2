// One control period of the simulation as named stages, in one place:
//
//   observe    perception, then every source gets the state of this tick
//              (frames out, in-process agents run)
//   collect    every source's answers to this tick (a lockstep source waits)
//   check      every command through the one CommandGate (sources check as
//              they receive; nothing reaches the world unchecked)
//   apply      the checked commands set on the world
//   step       World::stepControlPeriod (physics and sensors)
//   officials  the referee and the operator (Officials), events read after it
//   record     the period's record to every Recorder (log, statistics)
//   cameras    captures due at the new tick go to the render thread
//
// Serial mode runs them in that order: the command answering tick t acts in
// period t. Pipelined mode applies the answers to tick t-1, steps, and then
// collects the answers to tick t, so the drivers compute while the world
// steps: a fixed one-period actuation delay, the same for every source, as
// on the real Nao where a command from cycle k acts in a later cycle.
// Both are deterministic: the period never depends on when an answer came.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/sim/command.hpp"
#include "simsoccer/sim/events.hpp"
#include "simsoccer/world/camera_system.hpp"
#include "simsoccer/world/perception.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::sim {

enum class Mode : uint8_t { Serial, Pipelined };
// The mode of matches, benchmarks and in-process agents unless they are told otherwise:
// pipelined, as on a real robot, where a command computed from one sensor packet acts in a
// later cycle; physics and agents overlap on two cores.
inline constexpr Mode kDefaultMode = Mode::Pipelined;
// The default of a run in lockstep (kDefaultMode) or paced to the wall clock: serial there. A
// paced period collects right after observe the answers that came during the last period's
// wait, the same one period of delay as pipelined lockstep; pipelined, it collected them right
// after the step, about 1 ms after the frames went out, and an answer waited a period more (a
// LoLA client's answer to sensor map N showed in map N + 3, not N + 2 as in lockstep).
constexpr Mode defaultMode(bool lockstep) {
  return lockstep ? kDefaultMode : Mode::Serial;
}
const char* modeName(Mode m);
// "serial" or "pipelined"; throws std::invalid_argument naming the value.
Mode parseMode(const std::string& name);

struct SimulationConfig {
  // The plain period (no delay) unless a program asks: programs pass kDefaultMode or their
  // --mode; replay is serial (the log holds the commands each period applied).
  Mode mode = Mode::Serial;
  // Lockstep: cameras wait for the renderer when it falls behind. Real
  // time: captures are dropped (and counted) instead.
  bool lockstep = true;
  double position_margin = 0.5;  // rad beyond a joint's limits before a target is refused
  // Pipelined: RunLoop runs the periods on a CPU of their own, the other
  // threads and the agent processes on the rest (sim/cores.hpp).
  bool own_core = true;
  // Spectator camera images (on the conversion thread); robots' images go
  // to the image sinks of the sources.
  std::function<void(const world::CameraImage&)> spectator_sink;
};

// Wall time per stage, summed over the periods run (the per-period report of
// every program and benchmark).
struct Profile {
  double observe_s = 0.0;    // perception and sending the state
  double perception_s = 0.0;  // of observe_s: the perception
  double collect_s = 0.0;    // waiting for and taking the answers
  double apply_s = 0.0;      // setting the checked commands
  double step_s = 0.0;       // physics and sensors
  double officials_s = 0.0;  // the sources' after-step bookkeeping, referee and operator
  double record_s = 0.0;     // recorders (log, statistics)
  double camera_s = 0.0;     // capturing for the render thread (and waiting for it)
  double longest_collect_s = 0.0;  // the longest one period waited for its answers
  uint64_t periods = 0;
  double total() const {
    return observe_s + collect_s + apply_s + step_s + officials_s + record_s + camera_s;
  }
};

// Per robot: commands applied, refused by the gate, and periods its driver
// did not answer in time. (Applied and missed are kept by the period, on the
// thread that runs it: read them there.)
struct CommandStats {
  uint64_t accepted = 0, rejected = 0, missed = 0;
};

// The referee and the operator: run once per period after the step.
class Officials {
 public:
  virtual ~Officials() = default;
  // New events since the last call are appended.
  virtual void afterStep(std::vector<Event>& events) = 0;
  virtual referee::ControlData controlData() const = 0;
  virtual int leftTeam() const = 0;  // the team index controlData().teams[0] describes
  // Before afterStep: the team messages each team (index) has sent so far.
  virtual void teamMessages(int /*team*/, uint64_t /*total*/) {}
};

// What a period did, for the recorders.
struct PeriodRecord {
  uint64_t tick = 0;  // the period just completed (World::controlTick() before the step)
  const world::World* world = nullptr;
  // Per robot: the command applied in this period (quantised), if one was.
  const std::vector<RobotCommand>* commands = nullptr;
  const std::vector<bool>* commanded = nullptr;
  const std::vector<Event>* events = nullptr;     // this period's, from the officials
  const referee::ControlData* game = nullptr;     // after the officials (null: none)
};

class Recorder {
 public:
  virtual ~Recorder() = default;
  virtual void record(const PeriodRecord& p) = 0;
};

class Simulation {
 public:
  // The world must outlive the simulation. Perception and cameras are on
  // when the world's scenario turns them on.
  Simulation(world::World& world, const SimulationConfig& config = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Wiring, before the first period. Sources answer for disjoint robots (a
  // later source's answer for the same robot wins).
  void addSource(CommandSource& source);
  // The referee and operator (none: no game state). Takes its game state at once.
  void setOfficials(Officials* officials);
  void addRecorder(Recorder& recorder);
  // Robot camera images (on the conversion thread). Before the first period.
  void addImageSink(std::function<void(const world::CameraImage&)> sink);

  // One control period (the stages above).
  void period();

  world::World& world() { return world_; }
  const world::World& world() const { return world_; }
  const SimulationConfig& config() const { return config_; }
  Mode mode() const { return config_.mode; }
  CommandGate& gate() { return gate_; }
  const world::PerceptionSystem* perception() const { return perception_.get(); }
  const world::CameraSystem* cameras() const { return cameras_.get(); }
  // Delivers every image captured so far.
  void flushCameras();
  // Forgets robot r's answer waiting for the next period (pipelined mode): a
  // transport that frees a robot (its driver crashed) calls it, so the freed
  // robot's hold or limp targets are not overridden by its last answer.
  void dropPending(world::RobotId r);
  const Profile& profile() const { return profile_; }
  CommandStats commandStats(world::RobotId r) const;
  // The command applied to robot r in the last period, if one was.
  bool commandApplied(world::RobotId r) const { return commanded_.at(r); }
  const RobotCommand& appliedCommand(world::RobotId r) const { return applied_.at(r); }
  // The game state now (after the last officials stage), if officials run.
  std::optional<referee::ControlData> game() const;

 private:
  void observe(uint64_t tick);
  void collect(uint64_t tick);
  void apply();
  void ensureCameras();

  world::World& world_;
  SimulationConfig config_;
  CommandGate gate_;
  std::vector<CommandSource*> sources_;
  std::vector<Recorder*> recorders_;
  Officials* officials_ = nullptr;
  std::unique_ptr<world::PerceptionSystem> perception_;
  std::vector<std::function<void(const world::CameraImage&)>> image_sinks_;
  // The answers the next apply() takes (serial: to this tick; pipelined: to
  // the last one; none before the first collect), and the buffer collect()
  // fills before the two are swapped.
  std::vector<CommandSlot> due_, collected_;
  // World::placements per robot when the frames were observed that collected_ / due_ answer:
  // an answer to a frame from before the robot's last placement is not applied (pipelined, a
  // robot the referee moved at the end of a period got its answer to the frame before the move:
  // a K1 placed mid-kick, its leg jerked back towards the kick, tipped over). The robot holds
  // the targets it was placed with for that period.
  std::vector<uint64_t> observed_placements_, due_placements_;
  std::vector<RobotCommand> applied_;    // per robot, the last applied
  std::vector<bool> commanded_;          // per robot, applied in the last period
  std::vector<uint64_t> accepted_, missed_;
  std::optional<referee::ControlData> game_;
  std::vector<Event> events_;
  Profile profile_;
  bool cameras_started_ = false;
  std::unique_ptr<world::CameraSystem> cameras_;  // declared last: stopped first
};

}  // namespace simsoccer::sim
