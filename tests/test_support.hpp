// Shared helpers for the test suites: paths to the project's data files and
// small scenarios built in code.
#pragma once

#include <ifaddrs.h>
#include <net/if.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
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
// True if an interface other than loopback is up and can multicast (what
// configs/dds/lan.xml needs).
inline bool hasMulticastInterface() {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return false;
  bool found = false;
  for (const ifaddrs* a = list; a && !found; a = a->ifa_next)
    found = a->ifa_addr && a->ifa_addr->sa_family == AF_INET && (a->ifa_flags & IFF_UP) &&
            (a->ifa_flags & IFF_MULTICAST) && !(a->ifa_flags & IFF_LOOPBACK);
  freeifaddrs(list);
  return found;
}

// Packets sent on all interfaces but loopback (/proc/net/dev).
inline unsigned long long networkPacketsSent() {
  std::ifstream in("/proc/net/dev");
  std::string line;
  unsigned long long total = 0;
  while (std::getline(in, line)) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    name.erase(0, name.find_first_not_of(' '));
    if (name == "lo") continue;
    std::istringstream fields(line.substr(colon + 1));
    unsigned long long v[10] = {};
    for (auto& x : v) fields >> x;  // received: 8 fields; sent: bytes, packets, ...
    total += v[9];
  }
  return total;
}
inline std::filesystem::path dataDir() {
  return sourceDir() / "tests" / "data";
}
inline std::filesystem::path naoH25() {
  return sourceDir() / "robots" / "nao_v6_h25.yaml";
}
inline std::filesystem::path naoH21() {
  return sourceDir() / "robots" / "nao_h21.yaml";
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
