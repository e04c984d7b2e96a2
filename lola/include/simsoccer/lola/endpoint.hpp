// The LoLA transport: one Unix stream socket per robot it drives, speaking
// as a Nao V6's LoLA does, so that a team's robot binary plays in the
// simulation unmodified. A command source of the period pipeline.
//
// Per period (one LoLA cycle, 12 ms of simulated time): observe sends the
// robot's 896-byte sensor map; collect takes the maps the client sent since
// (lockstep: waits for at least one, up to the timeout; real time: takes
// what has arrived) and merges them into the robot's command, which goes
// through the one CommandGate. A client that connects gets the latest map
// at once; one client per robot (a new one replaces the old session). What
// a client does wrong (garbage, a NaN, a 10 MB map, silence) ends at most
// its own session: the robot holds its last command and the fault is counted.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "simsoccer/lola/actuator_stream.hpp"
#include "simsoccer/lola/sensor_packet.hpp"
#include "simsoccer/sim/command.hpp"

namespace simsoccer::lola {

struct RobotSocket {
  world::RobotId robot = 0;
  std::filesystem::path socket;  // where the endpoint listens (an old file there is replaced)
  RobotIdentity identity;
  double battery_charge = 1.0;  // at the start
  // The Webots LoLA controller's convention: Battery[3] (the temperature) carries the LoLA
  // cycle counter (u16, wrapping), which Bembelbots' code takes for the simulated time (tick x
  // 12 ms) when the head id is the simulator's. False: a constant 30 deg C.
  bool tick_in_battery = true;
};

struct EndpointConfig {
  std::vector<RobotSocket> robots;
  bool lockstep = true;
  double answer_timeout = 0.5;  // s of wall time a lockstep period waits for an answer
  // Lockstep stops waiting for a client that missed this many periods in a
  // row (it is hung or stopped), until it answers this many in a row again.
  int unresponsive_after = 3;
  // Lockstep: s of wall time the periods wait for a client that went away to connect again
  // (B-Human's binary reads the body id, closes and connects again when it has booted; a
  // watchdog restarts a crashed one), once per disconnection and at most three times between
  // two periods it answers (a binary in a crash loop is then not waited for); one period
  // waits at most answer_timeout + reconnect_timeout. 0: not waited for. Without it the
  // simulation ran on at its own speed meanwhile, and the robot missed the kick-off. (DDS
  // agents beside it get no frame meanwhile: a match gives them --gone-after beyond it.)
  double reconnect_timeout = 0.0;
  // Sensor maps a client may leave unread before new ones are dropped
  // (whole, so the stream stays framed), as LoLA ignores a client that does not read.
  std::size_t max_unread_packets = 3;
};

struct RobotLolaStats {
  bool connected = false;
  uint64_t sessions = 0;          // clients accepted
  uint64_t packets_sent = 0;      // sensor maps written whole
  uint64_t packets_dropped = 0;   // not written: the client was not reading
  uint64_t answered = 0;          // periods with at least one new map
  uint64_t missed = 0;            // lockstep periods without an answer in time
  uint64_t no_client = 0;         // periods without a connected client
  uint64_t maps = 0, bad_maps = 0, unknown_keys = 0, bytes_received = 0;
  uint64_t stream_errors = 0;     // sessions ended for unreadable input
  uint64_t refused = 0;           // merged commands the gate refused (NaN, out of range)
};

class Endpoint : public sim::CommandSource {
 public:
  // Opens every robot's socket. Throws std::invalid_argument when a robot
  // is not a Nao in LoLA's joint order, the world's control period is not
  // LoLA's 12 ms, or a socket path is too long or cannot be bound.
  Endpoint(const world::World& world, EndpointConfig config);
  ~Endpoint() override;
  Endpoint(const Endpoint&) = delete;
  Endpoint& operator=(const Endpoint&) = delete;

  void observe(const sim::Observation& o) override;
  void collect(uint64_t tick, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) override;

  // Accepts clients until every robot has one or the timeout passes (each
  // new client gets the current sensor map at once). True if all connected.
  bool waitForClients(double timeout_seconds);
  std::size_t connectedCount() const;
  const EndpointConfig& config() const { return config_; }
  // Per robot of the config, in its order.
  RobotLolaStats stats(std::size_t i) const;
  // The LEDs and other values the client set last.
  const ActuatorValues& actuators(std::size_t i) const;

 private:
  struct Client;
  using Clock = std::chrono::steady_clock;
  void acceptAll();
  void startSession(Client& c, int fd);
  void endSession(Client& c);
  void send(Client& c);
  void flush(Client& c);
  // Reads what the client sent (up to 64 KiB); false when the session ended.
  bool receive(Client& c);
  // Takes the maps read so far, in lockstep up to this cycle's answer.
  void parse(Client& c, bool until_answered);
  bool pollOnce(Clock::time_point deadline, bool wait);

  EndpointConfig config_;
  std::vector<Client> clients_;
  double cycle_seconds_;
  bool observed_ = false;
};

}  // namespace simsoccer::lola
