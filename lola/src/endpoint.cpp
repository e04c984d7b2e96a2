#include "simsoccer/lola/endpoint.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "simsoccer/protocol/wire.hpp"

namespace simsoccer::lola {

struct Endpoint::Client {
  RobotSocket config;
  int listen_fd = -1, fd = -1;
  ActuatorStream stream{ActuatorValues{}};
  std::vector<uint8_t> unsent;   // the tail of sensor maps the socket did not take yet
  SensorPacket latest{};         // this period's sensor map
  bool has_latest = false;
  bool latest_sent = false;      // this period's map went out (or was dropped)
  BatteryModel battery;
  // Sensor maps sent whose answer (a map that sets joints) has not come yet:
  // 1 after a map goes out; 2 when the last cycle's answer is also late (a
  // late answer is taken for its own cycle, not the next one; older ones
  // are forgiven).
  int owed = 0;
  bool new_joints = false;  // a map that sets joints was taken since the last collect
  int missed_in_row = 0, answered_in_row = 0;
  bool unresponsive = false;  // lockstep does not wait for it until it answers again
  // Lockstep waits for it to connect again until then (EndpointConfig::reconnect_timeout).
  std::optional<std::chrono::steady_clock::time_point> return_by;
  // Waits for it granted since it last answered a period: a binary that crashes and is
  // restarted over and over (or connects and closes without answering) is not waited for
  // beyond kReconnectWaits of them.
  int reconnect_waits = 0;
  std::array<float, kJoints> accepted_position{}, accepted_stiffness{};
  RobotLolaStats stats;
  Client(const RobotSocket& c) : config(c), battery(c.battery_charge) {}
};

namespace {
// Reconnection waits granted to a client between two periods it answers.
constexpr int kReconnectWaits = 3;

std::string errnoText() {
  return std::strerror(errno);
}

int listenOn(const std::filesystem::path& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::string p = path.string();
  if (p.size() >= sizeof address.sun_path)
    throw std::invalid_argument("lola: socket path '" + p + "' is " + std::to_string(p.size()) +
                                " characters; a Unix socket path has at most " +
                                std::to_string(sizeof address.sun_path - 1));
  std::memcpy(address.sun_path, p.c_str(), p.size() + 1);
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  if (std::filesystem::is_socket(path, ec))
    std::filesystem::remove(path, ec);  // a socket left by an earlier run
  else if (std::filesystem::exists(path, ec))
    throw std::invalid_argument("lola: '" + p + "' exists and is not a socket");
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error("lola: socket: " + errnoText());
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(fd, 4) != 0) {
    const std::string why = errnoText();
    ::close(fd);
    throw std::invalid_argument("lola: cannot listen on '" + p + "': " + why);
  }
  return fd;
}
}  // namespace

Endpoint::Endpoint(const world::World& world, EndpointConfig config)
    : config_(std::move(config)), cycle_seconds_(world.scenario().physics.control_period) {
  if (std::abs(cycle_seconds_ - kCycleSeconds) > 1e-9)
    throw std::invalid_argument(
        "lola: LoLA robots need a 12 ms control period (physics.control_period: 0.012 in the "
        "scenario '" + world.scenario().name + "'; it is " + std::to_string(cycle_seconds_) + ")");
  clients_.reserve(config_.robots.size());
  try {
    for (const RobotSocket& r : config_.robots) {
      if (r.robot >= world.robotCount())
        throw std::invalid_argument("lola: robot index " + std::to_string(r.robot) +
                                    " is not in the scenario");
      const auto& actuators = world.robot(r.robot).model->actuators;
      const world::RobotInfo& info = world.robot(r.robot);
      bool nao = actuators.size() == protocol::kActuators;
      for (std::size_t j = 0; nao && j < actuators.size(); ++j)
        nao = actuators[j].name == protocol::kNaoActuatorOrder[j];
      if (!nao)
        throw std::invalid_argument("lola: robot " + std::to_string(info.team) + ":" +
                                    std::to_string(info.number) +
                                    " is not a Nao in LoLA's joint order (its model '" +
                                    info.model->name + "')");
      checkIdentity(r.identity);
      clients_.emplace_back(r);
      Client& c = clients_.back();
      c.listen_fd = listenOn(r.socket);
      const world::SensorFrame& f = world.sensorFrame(r.robot);
      c.accepted_position = f.target;
      c.accepted_stiffness = f.stiffness;
    }
  } catch (...) {
    for (Client& c : clients_)
      if (c.listen_fd >= 0) {
        ::close(c.listen_fd);
        std::error_code ec;
        std::filesystem::remove(c.config.socket, ec);
      }
    throw;
  }
}

Endpoint::~Endpoint() {
  for (Client& c : clients_) {
    if (c.fd >= 0) ::close(c.fd);
    if (c.listen_fd >= 0) ::close(c.listen_fd);
    std::error_code ec;
    std::filesystem::remove(c.config.socket, ec);
  }
}

std::size_t Endpoint::connectedCount() const {
  std::size_t n = 0;
  for (const Client& c : clients_) n += c.fd >= 0;
  return n;
}

RobotLolaStats Endpoint::stats(std::size_t i) const {
  const Client& c = clients_.at(i);
  RobotLolaStats s = c.stats;  // earlier sessions, and this one's stream:
  s.connected = c.fd >= 0;
  s.maps += c.stream.counts().maps;
  s.bad_maps += c.stream.counts().bad_maps;
  s.unknown_keys += c.stream.counts().unknown_keys;
  s.bytes_received += c.stream.counts().bytes;
  return s;
}

const ActuatorValues& Endpoint::actuators(std::size_t i) const {
  return clients_.at(i).stream.values();
}

void Endpoint::startSession(Client& c, int fd) {
  if (c.fd >= 0) endSession(c);  // one client per robot: the newest wins
  // A small send buffer: a client that stops reading fills it within a few
  // maps, and the rest are dropped whole instead of queueing for seconds.
  const int bytes = static_cast<int>(config_.max_unread_packets * kSensorPacketBytes);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &bytes, sizeof bytes);
  c.fd = fd;
  c.return_by.reset();
  ++c.stats.sessions;
  c.unsent.clear();
  c.owed = 0;
  c.missed_in_row = c.answered_in_row = 0;
  c.unresponsive = false;
  ActuatorValues initial = c.stream.values();
  initial.position = c.accepted_position;
  initial.stiffness = c.accepted_stiffness;
  const StreamCounts before = c.stream.counts();
  c.stream = ActuatorStream(initial);
  c.stats.maps += before.maps;
  c.stats.bad_maps += before.bad_maps;
  c.stats.unknown_keys += before.unknown_keys;
  c.stats.bytes_received += before.bytes;
  if (c.has_latest) send(c);  // LoLA speaks first
}

void Endpoint::endSession(Client& c) {
  if (c.fd < 0) return;
  ::close(c.fd);
  c.fd = -1;
  c.unsent.clear();  // what the client sent before it went is still taken (parse)
  if (config_.lockstep && config_.reconnect_timeout > 0.0 && c.reconnect_waits < kReconnectWaits) {
    ++c.reconnect_waits;
    c.return_by = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(config_.reconnect_timeout));
  }
}

void Endpoint::acceptAll() {
  for (Client& c : clients_) {
    for (;;) {
      const int fd = ::accept4(c.listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) break;
      startSession(c, fd);
    }
  }
}

void Endpoint::flush(Client& c) {
  while (c.fd >= 0 && !c.unsent.empty()) {
    const ssize_t n = ::send(c.fd, c.unsent.data(), c.unsent.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n > 0) {
      c.unsent.erase(c.unsent.begin(), c.unsent.begin() + n);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return;
    endSession(c);  // the client went away
  }
}

void Endpoint::send(Client& c) {
  flush(c);
  if (c.fd < 0) return;
  c.latest_sent = true;
  if (!c.unsent.empty()) {  // the client is not reading: this map is dropped whole
    ++c.stats.packets_dropped;
    return;
  }
  c.unsent.assign(c.latest.begin(), c.latest.end());
  flush(c);
  ++c.stats.packets_sent;
  c.owed = std::min(c.owed, 1) + 1;
}

bool Endpoint::receive(Client& c) {
  // At most 64 KiB per call: a client that writes faster than it is read
  // cannot keep the period here (the stream ends it past its limit).
  uint8_t buffer[4096];
  for (std::size_t taken = 0; taken < 64 * 1024;) {
    const ssize_t n = ::recv(c.fd, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n > 0) {
      taken += static_cast<std::size_t>(n);
      try {
        c.stream.append(std::span<const uint8_t>(buffer, static_cast<std::size_t>(n)));
      } catch (const StreamError&) {
        ++c.stats.stream_errors;
        endSession(c);
        return false;
      }
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return true;
    endSession(c);  // closed (0) or failed
    return false;
  }
  return true;
}

void Endpoint::parse(Client& c, bool until_answered) {
  // In lockstep the maps after a cycle's answer wait for the next period:
  // what a period applies then depends on the stream's order alone, not on
  // when the bytes came.
  try {
    while (!(until_answered && c.owed == 0)) {
      const std::optional<bool> joints = c.stream.next();
      if (!joints) break;
      if (*joints) {
        c.new_joints = true;
        if (c.owed > 0) --c.owed;
      }
    }
  } catch (const StreamError&) {
    ++c.stats.stream_errors;
    endSession(c);
  }
}

bool Endpoint::pollOnce(Clock::time_point deadline, bool wait) {
  std::vector<pollfd> fds;
  fds.reserve(2 * clients_.size());
  for (Client& c : clients_) {
    fds.push_back({c.listen_fd, POLLIN, 0});
    fds.push_back({c.fd, static_cast<short>(POLLIN | (c.unsent.empty() ? 0 : POLLOUT)), 0});
  }
  int timeout_ms = 0;
  if (wait) {
    const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now());
    if (left.count() <= 0) return false;
    timeout_ms = static_cast<int>((left.count() + 999) / 1000);
  }
  const int ready = ::poll(fds.data(), fds.size(), timeout_ms);
  // Interrupted by a signal (Ctrl-C): the wait ends, and the run loop sees the stop.
  if (ready < 0 && errno == EINTR) return false;
  if (ready <= 0) return wait && Clock::now() < deadline;
  for (std::size_t i = 0; i < clients_.size(); ++i) {
    Client& c = clients_[i];
    if (fds[2 * i].revents & POLLIN) acceptAll();
    if (c.fd >= 0 && fds[2 * i + 1].fd == c.fd) {
      if (fds[2 * i + 1].revents & POLLOUT) flush(c);
      if (c.fd >= 0 && (fds[2 * i + 1].revents & (POLLIN | POLLHUP | POLLERR))) {
        receive(c);
        parse(c, config_.lockstep);
      }
    }
  }
  return true;
}

bool Endpoint::waitForClients(double timeout_seconds) {
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_seconds));
  acceptAll();
  while (connectedCount() < clients_.size())
    if (!pollOnce(deadline, true) && Clock::now() >= deadline) break;
  return connectedCount() == clients_.size();
}

void Endpoint::observe(const sim::Observation& o) {
  for (Client& c : clients_) {
    const world::SensorFrame& f = o.world->sensorFrame(c.config.robot);
    if (observed_) c.battery.update(f, cycle_seconds_);
    Battery battery = c.battery.reading();
    if (c.config.tick_in_battery) battery.temperature = static_cast<float>(o.tick & 0xffff);
    c.latest = encodeSensorPacket(fromFrame(f, battery), c.config.identity);
    c.has_latest = true;
    c.latest_sent = false;
  }
  observed_ = true;
  acceptAll();  // a new client gets this map at once
  for (Client& c : clients_) {
    // A late answer to the last cycle that has come meanwhile is taken for
    // that cycle before this cycle's map goes out.
    if (c.fd >= 0) {
      receive(c);
      parse(c, config_.lockstep);
    }
    if (c.fd >= 0 && !c.latest_sent) send(c);
  }
}

void Endpoint::collect(uint64_t, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) {
  const auto awaited = [&](const Client& c) {
    return c.fd >= 0 && c.owed > 0 && !c.unresponsive;
  };
  if (config_.lockstep) {
    const auto start = Clock::now();
    const auto seconds = [](double s) {
      return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
    };
    auto deadline = start + seconds(config_.answer_timeout);
    // However often clients go and come back, one period waits at most this long.
    const auto latest = deadline + seconds(config_.reconnect_timeout);
    // A client that went away: waited for until it is back (its map goes out as it connects,
    // then its answer is awaited) or its time is up.
    const auto returning = [&](const Client& c) {
      return c.fd < 0 && c.return_by && Clock::now() < *c.return_by;
    };
    for (;;) {
      bool waiting = false;
      for (const Client& c : clients_) {
        const bool back_soon = returning(c);
        waiting = waiting || awaited(c) || back_soon;
        if (back_soon)  // (also one gone during this wait)
          deadline = std::min(std::max(deadline, *c.return_by), latest);
      }
      if (!waiting || !pollOnce(deadline, true)) break;
    }
    for (Client& c : clients_)
      if (c.fd < 0 && c.return_by && !returning(c)) c.return_by.reset();  // not waited for again
  } else {
    for (Client& c : clients_) {  // whatever has arrived
      if (c.fd >= 0) receive(c);
      parse(c, false);
    }
  }
  for (Client& c : clients_) {
    sim::CommandSlot& slot = slots[c.config.robot];
    const bool answered = c.new_joints && (!config_.lockstep || c.owed == 0);
    c.new_joints = false;
    if (!answered) {
      if (c.fd < 0) {
        ++c.stats.no_client;  // holds its last command
      } else if (config_.lockstep) {
        ++c.stats.missed;
        c.answered_in_row = 0;
        // Three misses in a row: not waited for until it answers three
        // periods in a row (a client that answers now and then cannot slow
        // the game by the timeout every few periods).
        if (++c.missed_in_row >= config_.unresponsive_after) c.unresponsive = true;
        slot.answer = sim::Answer::Missed;
      }
      continue;
    }
    ++c.stats.answered;
    c.reconnect_waits = 0;
    c.missed_in_row = 0;
    if (++c.answered_in_row >= config_.unresponsive_after) c.unresponsive = false;
    const ActuatorValues& v = c.stream.values();
    auto command = gate.check(c.config.robot, std::span<const float>(v.position),
                              std::span<const float>(v.stiffness));
    if (!command) {
      ++c.stats.refused;  // the robot holds; the client's next map starts from the last good one
      c.stream.restoreJoints(c.accepted_position, c.accepted_stiffness);
      continue;
    }
    c.accepted_position = v.position;
    c.accepted_stiffness = v.stiffness;
    slot.answer = sim::Answer::Given;
    slot.command = *command;
  }
}

}  // namespace simsoccer::lola
