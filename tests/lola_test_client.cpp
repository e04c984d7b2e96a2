// A LoLA client written for the tests and the docs' worked example, strict
// like the strictest team code: connects to the socket (default
// /tmp/robocup, retrying as team code does), reads each sensor map with one
// recv of 896 bytes and checks every key, type and length (lola_reader.hpp),
// and answers with actuator maps packed by msgpack-c (whole-number floats
// become integers, as in NaoTH, rUNSWift and nao_lola). Modes play the
// behaviours and faults the simulator must survive.
//
//   simsoccer-lola-test-client [--socket P] [--mode M] [--cycles N] [--after K]
//       [--joint NAME=RAD]... [--stiffness S] [--expect-chest] [--print-id]
//       [--expect-id BODY_ID] [--ramp] [--expect-ticks] [--probe-gap S]
// modes: hold (answer every map, full), partial (full once, then Position
// alone, split over two writes, LEDs in a second map), probe (read one map,
// disconnect, reconnect --probe-gap s later, hold), flap (read one map, disconnect,
// reconnect, for ever: a crash loop), garbage, nan, huge (a 10 MB map), unknown
// (unknown keys in every map), silent (stop answering for K cycles after K),
// bump (hold, chest LEDs changing each cycle), late (one answer 0.8 s late), gc (no LoLA: on a
// field network, receive a GameController packet on 3838, send a status packet to
// --gc-host:3939, broadcast team messages to --broadcast:10000+team until
// one from a teammate arrives; --team-number, --player). --expect-ticks: Battery[3] carries the
// cycle counter (the Webots LoLA controller's convention), one more in each map.
// Exit: 0 done, 1 expectation not met, 2 usage, 3 protocol violation, 4 no server.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <msgpack.hpp>
#include <string>
#include <thread>
#include <vector>

#include "gc_reader.hpp"
#include "lola_reader.hpp"
#include "simsoccer/protocol/wire.hpp"

namespace {
using simsoccer::protocol::kNaoActuatorOrder;

int connectTo(const std::string& path) {
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::snprintf(a.sun_path, sizeof a.sun_path, "%s", path.c_str());
  for (int attempt = 0; attempt < 200; ++attempt) {  // 10 s, as team code retries
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) return fd;
    ::close(fd);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return -1;
}

bool writeAll(int fd, const char* data, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::send(fd, data, n, MSG_NOSIGNAL);
    if (w <= 0) return false;
    data += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

struct Options {
  std::string socket = "/tmp/robocup", mode = "hold";
  long cycles = 0, after = 50;
  std::vector<std::pair<int, float>> joints;
  float stiffness = 1.0f;
  bool expect_chest = false, print_id = false;
  std::string expect_id;  // the body id the robot must report
  int team_number = 0, player = 0;
  bool ramp = false;  // HeadYaw = 0.001 rad x the cycle: which cycle a command answers
  bool expect_ticks = false;
  double probe_gap = 0.0;  // s between the probe's close and its reconnection
  std::string gc_host, broadcast;
};

template <typename Values>
void packFloats(msgpack::packer<msgpack::sbuffer>& p, const char* key, const Values& v) {
  p.pack(std::string(key));
  p.pack_array(static_cast<uint32_t>(v.size()));
  for (float x : v) p.pack_float(x);
}
int udpSocket(uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  const int yes = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  ::setsockopt(fd, SOL_SOCKET, SO_BROADCAST, &yes, sizeof yes);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) return -1;
  return fd;
}

void sendTo(int fd, const std::string& host, uint16_t port, const void* data, std::size_t n) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  ::inet_pton(AF_INET, host.c_str(), &a.sin_addr);
  ::sendto(fd, data, n, 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
}

// What a team binary does on a field network, with the ports as on a field.
int fieldNetwork(const Options& o) {
  const int gc = udpSocket(3838);
  const auto team_port = static_cast<uint16_t>(10000 + o.team_number);
  const int team = udpSocket(team_port);
  if (gc < 0 || team < 0) {
    std::fprintf(stderr, "lola client: cannot bind 3838 and %u\n", team_port);
    return 4;
  }
  uint8_t buffer[1024];
  pollfd p{gc, POLLIN, 0};
  if (::poll(&p, 1, 10000) <= 0) {
    std::fprintf(stderr, "lola client: no GameController packet in 10 s\n");
    return 1;
  }
  const ssize_t n = ::recv(gc, buffer, sizeof buffer, 0);
  simsoccer::test::GcPacket packet;
  try {
    packet = simsoccer::test::readGcPacket(
        std::span<const uint8_t>(buffer, static_cast<std::size_t>(n)));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lola client: bad GameController packet: %s\n", e.what());
    return 3;
  }
  if (packet.teams[0].number != o.team_number && packet.teams[1].number != o.team_number) {
    std::fprintf(stderr, "lola client: my team %d is not playing\n", o.team_number);
    return 1;
  }
  std::printf("lola client: GameController packet v%d, state %d\n", packet.version, packet.state);
  // RoboCupGameControlReturnData v4: "RGrt", 4, player, team, fallen, pose, ballAge, ball.
  uint8_t status[32] = {'R', 'G', 'r', 't', 4};
  status[5] = static_cast<uint8_t>(o.player);
  status[6] = static_cast<uint8_t>(o.team_number);
  const float ball_age = -1.0f;
  std::memcpy(status + 20, &ball_age, 4);
  sendTo(gc, o.gc_host, 3939, status, sizeof status);
  const std::string hello = "hello from " + std::to_string(o.player);
  for (int attempt = 0; attempt < 40; ++attempt) {
    sendTo(team, o.broadcast, team_port, hello.data(), hello.size());
    pollfd t{team, POLLIN, 0};
    while (::poll(&t, 1, 250) > 0) {
      const ssize_t m = ::recv(team, buffer, sizeof buffer, 0);
      const std::string got(reinterpret_cast<char*>(buffer),
                            static_cast<std::size_t>(std::max<ssize_t>(m, 0)));
      if (got.rfind("hello from ", 0) == 0 && got != hello) {
        std::printf("lola client: teammate said '%s'\n", got.c_str());
        // A few more, so the teammate hears this one too.
        for (int k = 0; k < 4; ++k) {
          sendTo(team, o.broadcast, team_port, hello.data(), hello.size());
          std::this_thread::sleep_for(std::chrono::milliseconds(250));
        }
        return 0;
      }
    }
  }
  std::fprintf(stderr, "lola client: no teammate heard\n");
  return 1;
}
}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--socket")
      o.socket = value();
    else if (a == "--mode")
      o.mode = value();
    else if (a == "--cycles")
      o.cycles = std::stol(value());
    else if (a == "--after")
      o.after = std::stol(value());
    else if (a == "--stiffness")
      o.stiffness = std::stof(value());
    else if (a == "--expect-chest")
      o.expect_chest = true;
    else if (a == "--print-id")
      o.print_id = true;
    else if (a == "--ramp")
      o.ramp = true;
    else if (a == "--expect-ticks")
      o.expect_ticks = true;
    else if (a == "--probe-gap")
      o.probe_gap = std::stod(value());
    else if (a == "--expect-id")
      o.expect_id = value();
    else if (a == "--team-number")
      o.team_number = std::stoi(value());
    else if (a == "--player")
      o.player = std::stoi(value());
    else if (a == "--gc-host")
      o.gc_host = value();
    else if (a == "--broadcast")
      o.broadcast = value();
    else if (a == "--joint") {
      const std::string v = value();
      const auto eq = v.find('=');
      int index = -1;
      for (std::size_t j = 0; j < kNaoActuatorOrder.size(); ++j)
        if (eq != std::string::npos && v.substr(0, eq) == kNaoActuatorOrder[j])
          index = static_cast<int>(j);
      if (index < 0) {
        std::fprintf(stderr, "--joint %s: not NAME=RAD with a LoLA joint name\n", v.c_str());
        return 2;
      }
      o.joints.emplace_back(index, std::stof(v.substr(eq + 1)));
    } else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  if (o.mode == "gc") return fieldNetwork(o);
  int fd = connectTo(o.socket);
  if (fd < 0) {
    std::fprintf(stderr, "lola client: no server at %s\n", o.socket.c_str());
    return 4;
  }
  std::vector<float> hold;  // targets: the first map's positions, with --joint overrides
  long cycle = 0, silent_until = -1;
  float last_tick = -1.0f;  // --expect-ticks: Battery[3] of the last map
  bool probed = false, faulted = false, reconnected = false;
  std::vector<uint8_t> packet(896);
  for (; o.cycles == 0 || cycle < o.cycles; ++cycle) {
    const ssize_t n = ::recv(fd, packet.data(), packet.size(), 0);
    if (n <= 0) {
      if (faulted && !reconnected && (o.mode == "garbage" || o.mode == "huge")) {
        // The server ended the session over the fault: reconnect, as team code does.
        reconnected = true;
        ::close(fd);
        fd = connectTo(o.socket);
        if (fd < 0) return 4;
        std::printf("lola client: reconnected after the %s in map %ld\n", o.mode.c_str(), cycle);
        --cycle;
        continue;
      }
      std::printf("lola client: server closed after %ld cycles\n", cycle);
      break;
    }
    simsoccer::test::LolaSensors s;
    try {
      s = simsoccer::test::readLolaSensors(std::span<const uint8_t>(
          packet.data(), static_cast<std::size_t>(std::max<ssize_t>(n, 0))));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "lola client: protocol violation in map %ld: %s\n", cycle, e.what());
      return 3;
    }
    if (cycle == 0 && o.print_id) {
      std::printf("body id %s head id %s\n", s.robot_config[0].c_str(), s.robot_config[2].c_str());
      std::fflush(stdout);
    }
    if (cycle == 0 && !o.expect_id.empty() && s.robot_config[0] != o.expect_id) {
      std::fprintf(stderr, "lola client: robot %s, expected %s\n", s.robot_config[0].c_str(),
                   o.expect_id.c_str());
      return 1;
    }
    if (o.expect_ticks) {
      const float tick = s["Battery"][3];
      if (cycle > 0 && tick != std::fmod(last_tick + 1.0f, 65536.0f)) {
        std::fprintf(stderr, "lola client: map %ld has tick %.0f after %.0f\n", cycle, tick,
                     last_tick);
        return 1;
      }
      last_tick = tick;
    }
    if (o.expect_chest && s["Touch"][0] == 1.0f) {
      std::printf("lola client: chest button pressed in map %ld\n", cycle);
      return 0;
    }
    if (hold.empty()) {
      hold = s["Position"];
      for (auto [j, rad] : o.joints) hold[static_cast<std::size_t>(j)] = rad;
    }
    if (o.mode == "flap") {  // a binary in a crash loop: reads one map, goes, comes back
      ::close(fd);
      fd = connectTo(o.socket);
      if (fd < 0) break;
      continue;
    }
    if (o.mode == "probe" && !probed) {  // B-Human reads the body id and reconnects
      probed = true;
      ::close(fd);
      std::this_thread::sleep_for(std::chrono::duration<double>(o.probe_gap));  // booting
      fd = connectTo(o.socket);
      if (fd < 0) return 4;
      continue;
    }
    const bool fault_now = cycle >= o.after && !faulted;
    if (o.mode == "silent" && fault_now) {
      faulted = true;
      silent_until = cycle + o.after;
    }
    if (cycle < silent_until) continue;   // reads, does not answer
    if (o.mode == "late" && fault_now) {  // one answer after the simulator's timeout
      faulted = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(800));
    }
    if (o.mode == "garbage" && fault_now) {
      faulted = true;
      const char junk[] = "\xc1\xc1\xc1 not msgpack";
      writeAll(fd, junk, sizeof junk);
      continue;
    }
    if (o.mode == "huge" && fault_now) {
      faulted = true;
      msgpack::sbuffer big;
      msgpack::packer<msgpack::sbuffer> p(big);
      p.pack_map(1);
      p.pack(std::string("Position"));
      p.pack_array(10 * 1024 * 1024 / 5);
      for (int i = 0; i < 10 * 1024 * 1024 / 5; ++i) p.pack_float(0.5f);
      writeAll(fd, big.data(), big.size());  // fails: the server ends the session at the header
      continue;
    }
    msgpack::sbuffer out;
    msgpack::packer<msgpack::sbuffer> p(out);
    std::vector<float> position = hold, stiffness(25, o.stiffness);
    if (o.ramp) position[0] = 0.001f * static_cast<float>(cycle);
    if (o.mode == "nan" && fault_now) {
      faulted = true;
      position[0] = std::numeric_limits<float>::quiet_NaN();
    }
    const bool partial = o.mode == "partial" && cycle > 0;
    const bool unknown = o.mode == "unknown";
    p.pack_map(partial ? 1 : 11 + (unknown ? 2 : 0));
    packFloats(p, "Position", position);
    if (!partial) {
      packFloats(p, "Stiffness", stiffness);
      const float blue = o.mode == "bump" ? static_cast<float>(cycle % 2) : 1.0f;
      packFloats(p, "Chest", std::vector<float>{0.0f, 0.0f, blue});
      packFloats(p, "LEye", std::vector<float>(24, 0.5f));
      packFloats(p, "REye", std::vector<float>(24, 0.5f));
      packFloats(p, "LEar", std::vector<float>(10, 1.0f));
      packFloats(p, "REar", std::vector<float>(10, 1.0f));
      packFloats(p, "LFoot", std::vector<float>(3, 0.0f));
      packFloats(p, "RFoot", std::vector<float>(3, 0.0f));
      packFloats(p, "Skull", std::vector<float>(12, 0.0f));
      p.pack(std::string("Sonar"));
      p.pack_array(2);
      p.pack(true);
      p.pack(true);
      if (unknown) {
        packFloats(p, "Fan", std::vector<float>{1.0f});
        p.pack(std::string("SimulationTime"));
        p.pack(12.5);
      }
    }
    bool ok = true;
    if (partial) {  // split the map over two writes, then a second map (LEDs only)
      const std::size_t half = out.size() / 2;
      ok = writeAll(fd, out.data(), half);
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      ok = ok && writeAll(fd, out.data() + half, out.size() - half);
      msgpack::sbuffer leds;
      msgpack::packer<msgpack::sbuffer> q(leds);
      q.pack_map(1);
      packFloats(q, "Chest", std::vector<float>{1.0f, 0.0f, 0.0f});
      ok = ok && writeAll(fd, leds.data(), leds.size());
    } else {
      ok = writeAll(fd, out.data(), out.size());
    }
    if (!ok) {
      std::fprintf(stderr, "lola client: write failed in map %ld\n", cycle);
      return 1;
    }
  }
  ::close(fd);
  if (o.expect_chest) {
    std::fprintf(stderr, "lola client: the chest button was never pressed\n");
    return 1;
  }
  std::printf("lola client: %ld cycles\n", cycle);
  return 0;
}
