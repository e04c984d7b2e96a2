// Shared helpers for the test suites: paths to the project's data files and
// small scenarios built in code.
#pragma once

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "simsoccer/world/scenario.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::test {

inline std::filesystem::path sourceDir() {
  return SIMSOCCER_SOURCE_DIR;
}
// Runs a shell command; returns its stdout and stderr, `status` as pclose gives it.
inline std::string runCommand(const std::string& cmd, int& status) {
  std::string out;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return out;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) out += buf;
  status = pclose(p);
  return out;
}
// bubblewrap can make a mount namespace here (lola-run needs it; a
// container without user namespaces cannot).
inline bool bubblewrapWorks() {
  int status = -1;
  runCommand("bwrap --dev-bind / / --tmpfs /tmp --unshare-pid true", status);
  return status == 0;
}
inline std::string readFile(const std::filesystem::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
// A folder of this test process's own (name and process id: test runs side
// by side do not share it), empty when made (a leftover is removed first) and
// removed with what is in it when the test ends, passed or failed.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("simsoccer_test_" + name + "_" + std::to_string(getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;  // a destructor must not throw
    if (!path_.empty()) std::filesystem::remove_all(path_, ignored);
  }
  TempDir(TempDir&& other) noexcept : path_(std::move(other.path_)) { other.path_.clear(); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  TempDir& operator=(TempDir&&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& p) const { return path_ / p; }

 private:
  std::filesystem::path path_;
};
// The IPv4 address of an interface other than loopback that is up, running
// and can multicast (what configs/dds/lan.xml needs); none if there is none.
inline std::optional<in_addr> multicastInterfaceAddress() {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return std::nullopt;
  std::optional<in_addr> found;
  for (const ifaddrs* a = list; a && !found; a = a->ifa_next)
    if (a->ifa_addr && a->ifa_addr->sa_family == AF_INET && (a->ifa_flags & IFF_UP) &&
        (a->ifa_flags & IFF_RUNNING) && (a->ifa_flags & IFF_MULTICAST) &&
        !(a->ifa_flags & IFF_LOOPBACK))
      found = reinterpret_cast<const sockaddr_in*>(a->ifa_addr)->sin_addr;
  freeifaddrs(list);
  return found;
}

// Listens, on a network interface, for the RTPS participant announcements
// (SPDP) that Cyclone DDS multicasts for a domain: 239.255.0.1, port
// 7400 + 250 x domain (the RTPS specification's defaults). Created before the
// participants, it shares the port with them.
class SpdpMulticastListener {
 public:
  SpdpMulticastListener(uint32_t domain, in_addr interface_address) {
    fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    const int one = 1;
    setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    setsockopt(fd_, SOL_SOCKET, SO_REUSEPORT, &one, sizeof one);
    sockaddr_in at{};
    at.sin_family = AF_INET;
    at.sin_port = htons(static_cast<uint16_t>(7400 + 250 * domain));
    at.sin_addr.s_addr = htonl(INADDR_ANY);
    ip_mreq group{};
    inet_pton(AF_INET, "239.255.0.1", &group.imr_multiaddr);
    group.imr_interface = interface_address;
    ok_ = fd_ >= 0 && bind(fd_, reinterpret_cast<const sockaddr*>(&at), sizeof at) == 0 &&
          setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &group, sizeof group) == 0;
  }
  ~SpdpMulticastListener() {
    if (fd_ >= 0) close(fd_);
  }
  SpdpMulticastListener(const SpdpMulticastListener&) = delete;
  SpdpMulticastListener& operator=(const SpdpMulticastListener&) = delete;
  bool ok() const { return ok_; }
  // RTPS datagrams received so far (reads what is waiting).
  int received() {
    char buf[2048];
    ssize_t n;
    while ((n = recv(fd_, buf, sizeof buf, 0)) > 0)
      if (n >= 4 && std::memcmp(buf, "RTPS", 4) == 0) ++count_;
    return count_;
  }

 private:
  int fd_ = -1;
  bool ok_ = false;
  int count_ = 0;
};
inline std::filesystem::path dataDir() {
  return sourceDir() / "tests" / "data";
}
inline std::filesystem::path naoH25() {
  return sourceDir() / "robots" / "nao_v6_h25.yaml";
}
inline std::filesystem::path naoH21() {
  return sourceDir() / "robots" / "nao_h21.yaml";
}
inline std::filesystem::path boosterK1() {
  return sourceDir() / "robots" / "booster_k1.yaml";
}
inline std::filesystem::path splField() {
  return sourceDir() / "fields" / "spl.yaml";
}

// An SPL field scenario with the given robots (team 0, numbers 1..n, in a row).
inline world::Scenario scenario(int robots, uint64_t seed = 1) {
  world::Scenario s;
  s.name = "test";
  s.field_file = splField();
  s.robot_model_file = naoH25();
  s.seed = seed;
  s.ball_position = {3.0, 2.0, -1.0};
  for (int i = 0; i < robots; ++i) {
    world::RobotPlacement p;
    p.team = i % 2;
    p.number = i / 2 + 1;
    p.x = -3.5 + 0.7 * (i % 10);
    p.y = -1.0 + 1.0 * (i / 10);
    s.robots.push_back(p);
  }
  return s;
}

// The ball at rest on the carpet at (x, y).
inline void putBallOnCarpet(world::World& w, double x, double y) {
  engine::RigidBodyState b;
  b.pose.translation() = engine::Vec3(x, y, w.field().ball.radius);
  w.setBallState(b);
}

// The lines of a file (a benchmark's CSV: the header first); empty if it is missing.
// The cells of one CSV line (no quoting: the benches write plain cells).
inline std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> cells;
  size_t start = 0;
  for (;;) {
    const size_t comma = line.find(',', start);
    cells.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return cells;
    start = comma + 1;
  }
}

inline std::vector<std::string> readLines(const std::filesystem::path& file) {
  std::ifstream f(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(f, line);) lines.push_back(line);
  return lines;
}

// A bench run: `simsoccer ARGS --csv FILE` (the program's path: `bin`); its
// output, exit status (as pclose gives it) and the CSV's lines (header first),
// the file removed afterwards.
struct BenchRun {
  std::string out;
  int status = -1;
  std::vector<std::string> lines;
};
inline BenchRun runBench(const std::string& bin, const std::string& args) {
  static int serial = 0;
  const auto csv =
      std::filesystem::temp_directory_path() /
      ("simsoccer_bench_" + std::to_string(::getpid()) + "_" + std::to_string(serial++) + ".csv");
  std::filesystem::remove(csv);
  BenchRun r;
  r.out = runCommand(bin + " " + args + " --csv " + csv.string(), r.status);
  std::printf("%s", r.out.c_str());
  r.lines = readLines(csv);
  std::filesystem::remove(csv);
  return r;
}

}  // namespace simsoccer::test
