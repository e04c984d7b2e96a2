// Soak runs: whole matches back to back in this one process, with agent
// processes killed (SIGKILL) and frozen (SIGSTOP, then SIGCONT) at random
// simulated times, while the simulator's and the agents' memory, file
// descriptors and threads are sampled. What a tournament server does for a
// day, in an hour: a leak, a stuck restart or an unfinished game shows up.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "simsoccer/match/match_runner.hpp"
#include "simsoccer/match/match_session.hpp"

namespace simsoccer::match {

struct SoakOptions {
  int games = 10;
  int kills_per_game = 10;     // SIGKILL, at most restart_limit per agent and game
  int stops_per_game = 2;      // SIGSTOP, then SIGCONT after stop_seconds of wall time
  double stop_seconds = 3.0;   // below the agent's 10 s "simulator gone" wait
  uint64_t seed = 1;           // game k plays seed + k; the faults' times and victims too
  RunOptions run;              // out: the folder of game_K/ folders; video is turned off
};

// One process's figures: resident memory (MiB), open file descriptors, threads.
struct ProcessSample {
  double rss_mib = 0.0;
  double anon_mib = 0.0;  // of it, anonymous memory (heap, stacks): file-backed is code and data of libraries
  int fds = 0, threads = 0;
};
// /proc/PID/status and /proc/PID/fd (pid 0: this process); false if gone.
bool sampleProcess(int pid, ProcessSample& out);

struct SoakGame {
  int index = 0;
  uint64_t seed = 0;
  bool finished = false;          // played to its end: not aborted, not interrupted
  bool summary_complete = false;  // summary.json has every key a match writes
  std::string score;              // "2:3"
  double simulated = 0.0, wall = 0.0;
  int kills = 0, stops = 0, restarts = 0;
  double longest_wait = 0.0;  // s, the longest lockstep period
  ProcessSample sim_start, sim_end;
  // The simulator's heap in use (glibc's mallinfo2, MiB) before the game and
  // after it: what the game left allocated, whatever the RSS keeps.
  double heap_start = 0.0, heap_end = 0.0;
  double sim_peak_rss = 0.0;
  // Agents: the mean of their RSS at the game's first and last sample, and the largest seen.
  double agent_rss_start = 0.0, agent_rss_peak = 0.0, agent_rss_end = 0.0;
  std::string abort_reason;
};

struct SoakResult {
  std::vector<SoakGame> games;
  bool interrupted = false;
  // The checks, each with its reason when it failed.
  std::vector<std::string> failures;
  double rss_growth = 0.0;  // last game's simulator peak over the first's, minus 1
};

// Plays the games; `on_game` hears each as it ends.
SoakResult runSoak(const MatchConfig& config, const SoakOptions& o,
                   const std::function<void(const SoakGame&)>& on_game = {});

}  // namespace simsoccer::match
