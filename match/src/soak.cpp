#include "simsoccer/match/soak.hpp"

#include <dirent.h>
#include <malloc.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <set>
#include <sstream>

#include "simsoccer/match/outputs.hpp"
#include "simsoccer/net/robot_keys.hpp"

namespace simsoccer::match {
namespace {

using Clock = std::chrono::steady_clock;

// An agent process of this one: its pid and robot.
struct AgentPid {
  int pid = 0, team = -1, player = -1;
};

// The simsoccer-agent children of this process, from /proc (the runner owns
// them; the soak only signals them), in pid order.
std::vector<AgentPid> agentChildren() {
  std::vector<AgentPid> out;
  const int self = static_cast<int>(::getpid());
  DIR* proc = ::opendir("/proc");
  if (!proc) return out;
  while (const dirent* e = ::readdir(proc)) {
    const int pid = std::atoi(e->d_name);
    if (pid <= 0) continue;
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    // pid (comm) state ppid ...: comm may hold spaces, so read after the last ')'.
    const size_t close = line.rfind(')');
    const size_t open = line.find('(');
    if (close == std::string::npos || open == std::string::npos) continue;
    if (line.substr(open + 1, close - open - 1) != "simsoccer-agent") continue;
    std::istringstream rest(line.substr(close + 2));
    char state = 0;
    int ppid = 0;
    rest >> state >> ppid;
    if (ppid != self || state == 'Z') continue;
    AgentPid a;
    a.pid = pid;
    std::ifstream cmdline("/proc/" + std::to_string(pid) + "/cmdline");
    std::vector<std::string> args;
    for (std::string arg; std::getline(cmdline, arg, '\0');) args.push_back(arg);
    for (size_t i = 0; i + 1 < args.size(); ++i) {
      if (args[i] == "--team") a.team = std::atoi(args[i + 1].c_str());
      if (args[i] == "--player") a.player = std::atoi(args[i + 1].c_str());
    }
    out.push_back(a);
  }
  ::closedir(proc);
  std::sort(out.begin(), out.end(), [](const AgentPid& a, const AgentPid& b) { return a.pid < b.pid; });
  return out;
}

// The keys every summary.json of a finished match has.
bool summaryComplete(const std::filesystem::path& file) {
  std::ifstream f(file);
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string s = ss.str();
  if (s.empty() || s.find_last_not_of(" \n") == std::string::npos ||
      s[s.find_last_not_of(" \n")] != '}')
    return false;
  for (const char* key : {"final_score", "final_state_hash", "simulated_seconds", "wall_seconds",
                          "agent_restarts", "log_frames", "referee_events", "robots", "aborted",
                          "interrupted", "missed_commands", "longest_wait_seconds"})
    if (s.find("\"" + std::string(key) + "\":") == std::string::npos) return false;
  return true;
}

// MiB the program holds from malloc: in the arenas and mapped on its own (large blocks).
double heapInUse() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks + m.hblkhd) / (1024.0 * 1024.0);
}

}  // namespace

bool sampleProcess(int pid, ProcessSample& out) {
  const std::string dir = pid == 0 ? "/proc/self" : "/proc/" + std::to_string(pid);
  std::ifstream status(dir + "/status");
  if (!status) return false;
  bool rss = false;
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) {
      out.rss_mib = std::atof(line.c_str() + 6) / 1024.0;  // kB
      rss = true;
    } else if (line.rfind("RssAnon:", 0) == 0) {
      out.anon_mib = std::atof(line.c_str() + 8) / 1024.0;
    } else if (line.rfind("Threads:", 0) == 0) {
      out.threads = std::atoi(line.c_str() + 8);
    }
  }
  out.fds = 0;
  if (DIR* fd = ::opendir((dir + "/fd").c_str())) {
    while (const dirent* e = ::readdir(fd))
      if (e->d_name[0] != '.') ++out.fds;
    ::closedir(fd);
    if (pid == 0) --out.fds;  // the one opendir held
  }
  return rss;
}

SoakResult runSoak(const MatchConfig& config, const SoakOptions& o,
                   const std::function<void(const SoakGame&)>& on_game) {
  SoakResult result;
  // What a game initialises once per process, before the first baseline:
  // OpenCV's image codecs (its GDAL driver registry alone maps 8.5 MiB of
  // library pages when the first heatmap is written) and OpenSSL's random
  // generator (the match secret, 2 MiB). Measured with /proc/self/smaps: the
  // first game's peak would otherwise be that much lower than every later one's.
  std::vector<uint8_t> png;
  cv::imencode(".png", cv::Mat(1, 1, CV_8UC3, cv::Scalar(0, 0, 0)), png);
  (void)net::newMatchSecret();
  for (int k = 0; k < o.games; ++k) {
    SoakGame g;
    g.index = k + 1;
    g.seed = o.seed + static_cast<uint64_t>(k);
    RunOptions run = o.run;
    run.out = o.run.out / ("game_" + std::to_string(g.index));
    run.seed = g.seed;
    run.video = false;
    run.overwrite = true;  // this soak's own folder, checked when it started
    prepareOut(run.out, run.overwrite);
    g.heap_start = heapInUse();
    sampleProcess(0, g.sim_start);
    g.sim_peak_rss = g.sim_start.rss_mib;
    {
      MatchSession session(config, g.seed);
      // The faults' simulated times, spread over both halves and the break
      // between them (not the first 5 s: the agents are still claiming; the
      // stoppages make a game longer still), victims drawn when due.
      std::mt19937_64 rng(g.seed * 7919 + 17);
      const auto& rules = session.game().rules();
      std::uniform_real_distribution<double> when(
          5.0, std::max(6.0, 2.0 * rules.half_duration + rules.half_time_break));
      std::vector<double> kills(static_cast<size_t>(o.kills_per_game)),
          stops(static_cast<size_t>(o.stops_per_game));
      for (double& t : kills) t = when(rng);
      for (double& t : stops) t = when(rng);
      std::sort(kills.begin(), kills.end());
      std::sort(stops.begin(), stops.end());
      size_t next_kill = 0, next_stop = 0;
      std::map<int, int> killed;  // robot (team * 256 + player) -> kills this game
      // Killed, maybe not yet reaped: still a child, and SIGKILL to it succeeds again.
      std::set<int> killed_pids;
      std::vector<std::pair<int, Clock::time_point>> frozen;  // pid, when to continue
      bool first_sample = true;
      const auto sample = [&] {
        ProcessSample s;
        if (sampleProcess(0, s)) g.sim_peak_rss = std::max(g.sim_peak_rss, s.rss_mib);
        double sum = 0.0;
        int n = 0;
        for (const AgentPid& a : agentChildren()) {
          ProcessSample as;
          if (!sampleProcess(a.pid, as)) continue;
          sum += as.rss_mib;
          ++n;
          g.agent_rss_peak = std::max(g.agent_rss_peak, as.rss_mib);
        }
        if (n == 0) return;
        if (first_sample) g.agent_rss_start = sum / n;
        first_sample = false;
        g.agent_rss_end = sum / n;
      };
      run.progress = [&](const MatchSession& s, double wall) {
        if (o.run.progress) o.run.progress(s, wall);
        sample();
        const double t = s.world().time();
        const auto now = Clock::now();
        for (auto it = frozen.begin(); it != frozen.end();)
          if (now >= it->second) {
            ::kill(it->first, SIGCONT);
            it = frozen.erase(it);
          } else {
            ++it;
          }
        while (next_kill < kills.size() && t >= kills[next_kill]) {
          // The least-killed agent that is not frozen (ties: drawn).
          std::vector<AgentPid> candidates;
          int fewest = 1 << 30;
          for (const AgentPid& a : agentChildren()) {
            if (std::any_of(frozen.begin(), frozen.end(),
                            [&](auto& f) { return f.first == a.pid; }) ||
                killed_pids.count(a.pid))
              continue;
            const int n = killed[a.team * 256 + a.player];
            if (n >= config.restart_limit) continue;
            if (n < fewest) candidates.clear(), fewest = n;
            if (n == fewest) candidates.push_back(a);
          }
          if (candidates.empty()) break;  // restarts still coming up: next time
          const AgentPid& v = candidates[rng() % candidates.size()];
          if (::kill(v.pid, SIGKILL) == 0) {
            killed_pids.insert(v.pid);
            ++killed[v.team * 256 + v.player];
            ++g.kills;
          }
          ++next_kill;
        }
        while (next_stop < stops.size() && t >= stops[next_stop] && frozen.empty()) {
          const auto agents = agentChildren();
          if (agents.empty()) break;
          const AgentPid& v = agents[rng() % agents.size()];
          if (::kill(v.pid, SIGSTOP) == 0) {
            frozen.emplace_back(v.pid, now + std::chrono::duration_cast<Clock::duration>(
                                                 std::chrono::duration<double>(o.stop_seconds)));
            ++g.stops;
          }
          ++next_stop;
        }
      };
      RunResult r;
      try {
        r = playMatch(session, run);
      } catch (const std::exception& e) {  // a game that cannot run is a finding, not the end
        r.aborted = true;
        r.abort_reason = e.what();
      }
      // (A frozen agent is stopped with the rest: SIGKILL needs no SIGCONT.)
      g.finished = !r.aborted && !r.interrupted && session.over();
      g.abort_reason = r.abort_reason;
      g.restarts = static_cast<int>(r.agent_events.size());
      g.simulated = session.world().time();
      g.wall = r.wall;
      g.longest_wait = r.longest_wait;
      g.score = std::to_string(session.game().score(0)) + ":" + std::to_string(session.game().score(1));
      g.summary_complete = summaryComplete(run.out / "summary.json");
      result.interrupted = r.interrupted;
    }
    // After the session and its agents are gone: what the game left behind.
    // The freed memory goes back to the system, as a long-running server's
    // should between games (glibc keeps it in its per-thread arenas
    // otherwise, and the next game's peak would measure the allocator).
    malloc_trim(0);
    g.heap_end = heapInUse();
    sampleProcess(0, g.sim_end);
    result.games.push_back(g);
    if (on_game) on_game(g);
    if (result.interrupted) break;
  }
  // The checks.
  char buf[240];
  int kills = 0;
  for (const SoakGame& g : result.games) {
    kills += g.kills;
    if (!g.finished) {
      std::snprintf(buf, sizeof buf, "game %d did not finish%s%s", g.index,
                    g.abort_reason.empty() ? "" : ": ", g.abort_reason.c_str());
      result.failures.push_back(buf);
    }
    if (!g.summary_complete) {
      std::snprintf(buf, sizeof buf, "game %d: summary.json is incomplete", g.index);
      result.failures.push_back(buf);
    }
    if (g.restarts < g.kills) {
      std::snprintf(buf, sizeof buf, "game %d: %d kills but %d restarts", g.index, g.kills,
                    g.restarts);
      result.failures.push_back(buf);
    }
  }
  if (kills < o.games * o.kills_per_game && !result.interrupted) {
    std::snprintf(buf, sizeof buf, "%d kills of the %d planned", kills, o.games * o.kills_per_game);
    result.failures.push_back(buf);
  }
  if (result.games.size() >= 2) {
    const SoakGame& first = result.games.front();
    const SoakGame& last = result.games.back();
    result.rss_growth = last.sim_peak_rss / std::max(1e-9, first.sim_peak_rss) - 1.0;
    if (result.rss_growth >= 0.05) {
      std::snprintf(buf, sizeof buf,
                    "the simulator's peak RSS grew %.1f %% from the first game to the last (%.1f -> "
                    "%.1f MiB; limit 5 %%)",
                    100.0 * result.rss_growth, first.sim_peak_rss, last.sim_peak_rss);
      result.failures.push_back(buf);
    }
    if (last.sim_end.fds > first.sim_end.fds || last.sim_end.threads > first.sim_end.threads) {
      std::snprintf(buf, sizeof buf,
                    "after the last game the simulator holds %d file descriptors and %d threads, "
                    "after the first %d and %d",
                    last.sim_end.fds, last.sim_end.threads, first.sim_end.fds,
                    first.sim_end.threads);
      result.failures.push_back(buf);
    }
  }
  return result;
}

}  // namespace simsoccer::match
