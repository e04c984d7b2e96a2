// Playing a match or penalty kicks with agent processes: the simulation's
// period pipeline with the DDS transport, the session's officials and
// records, the match log as a recorder, agent supervision (restarts up to
// the limit), and the outputs (summary.json, heatmap.png, match.mp4).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/match/lola_robots.hpp"
#include "simsoccer/match/match_session.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "simsoccer/world/match_log.hpp"

namespace simsoccer::match {

struct RunOptions {
  std::filesystem::path out;  // the run's folder
  bool overwrite = false;     // replace an earlier run's files there (else refused)
  uint64_t seed = 1;
  bool realtime = false;  // paced to the wall clock instead of lockstep
  bool external = false;  // start no agents: wait for agents started elsewhere
  bool video = true;
  uint32_t domain = 0;
  std::filesystem::path dds_config;  // the simulator's and the agents' Cyclone configuration
  // DDS Security (simsoccer credentials): the simulator runs with
  // secure/simulator.xml and team T's agents with secure/team_T.xml
  // (replacing dds_config). Empty: no DDS Security.
  std::filesystem::path secure;
  double max_seconds = 0.0;          // > 0: stop after this much simulated time
  // Of the control period; unset: sim::defaultMode (pipelined in lockstep, serial in real time).
  std::optional<sim::Mode> mode;
  // Asked after every period: true stops the run (Ctrl-C), keeping what was recorded.
  std::function<bool()> stop_requested;
  // Called about every 0.25 s of wall time with the wall seconds so far.
  std::function<void(const MatchSession&, double wall)> progress;
  // Told what a person starting clients by hand needs to know (LoLA sockets).
  std::function<void(const std::string&)> notice;
};



struct RunResult {
  bool interrupted = false, aborted = false;
  std::string abort_reason;
  double wall = 0.0;
  uint64_t final_hash = 0;
  std::vector<std::string> agent_events;  // restarts, as JSON objects
  // Per robot (world order): lockstep periods its agent did not answer within
  // the timeout (the robot kept its last command: a cause for a changed game).
  std::vector<uint64_t> missed_commands;
  std::vector<world::LogEvent> events;
  int frames = 0;
  uint64_t log_bytes = 0;
  int video_frames = 0;  // playMatch: frames of match.mp4 (0: none written)
  std::vector<LolaResult> lola;  // per LoLA robot, in the config's order
  double longest_wait = 0.0;     // s of wall time the longest period waited for its answers
};

// The match log's header for a session (config, scenario, seed, robots).
world::MatchLogHeader logHeader(const MatchSession& s, const RunOptions& o);

// The command line of the agent process a match starts for robot (team,
// number): the config's role, behaviour and team number, the run's domain
// and DDS configuration, a seed from the run's seed and the robot. The same
// for a restart, and for agents started by hand for `simsoccer serve`.
std::vector<std::string> agentCommand(const MatchSession& session, const RunOptions& o, int team,
                                      int number);

// Plays one session (a game, or one penalty kick) with agents, logging to `log`.
RunResult play(MatchSession& session, const RunOptions& o, world::MatchLogWriter& log);

// A whole match into o.out: match.log, summary.json, and unless interrupted
// heatmap.png and (o.video) match.mp4. Throws when o.out cannot be written.
RunResult playMatch(MatchSession& session, const RunOptions& o);

// Makes the output folder and proves it is writable, before anything runs. A folder that holds
// an earlier run (its summary.json, match.log, penalty.json or a soak's game_1) is refused
// unless `overwrite`: the run would replace it.
void prepareOut(const std::filesystem::path& out, bool overwrite);

}  // namespace simsoccer::match

namespace simsoccer::match {

struct PenaltyResult {
  std::vector<std::string> outcomes;  // per kick: goal, saved, missed or timeout
  int goals = 0, saved = 0, missed = 0, timeout = 0;
  bool interrupted = false;
  std::vector<std::filesystem::path> videos;  // kick_K.mp4 written
};
// Penalty kicks (a penalty config): per kick a fresh session seeded o.seed+k
// with its agents; writes o.out/penalty.json, and kick_K.mp4 for the first
// `video_kicks` kicks. `on_kick` hears each outcome as it is known.
PenaltyResult playPenalties(
    const MatchConfig& config, const RunOptions& o, int kicks, int video_kicks,
    const std::function<void(int kick, uint64_t seed, const std::string& outcome)>& on_kick = {});

}  // namespace simsoccer::match
