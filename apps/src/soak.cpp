// simsoccer soak: whole matches back to back with agents killed and frozen,
// the simulator's and agents' memory, descriptors and threads sampled
// (simsoccer/match/soak.hpp); prints the table and the checks.
#include "simsoccer/match/soak.hpp"

#include <cstdio>

#include "cli.hpp"
#include "domain_option.hpp"
#include "simsoccer/world/scenario.hpp"

namespace simsoccer::apps {
namespace {

const char* kSoakHelp =
    "usage: simsoccer soak [CONFIG] [--games N] [--kills N] [--stops N] [--stop-seconds S]\n"
    "                      [--half S] [--seed N] [--out DIR] [--domain D] [--dds-config FILE]\n"
    "                      [--csv FILE] [--overwrite]\n"
    "\n"
    "Plays N whole matches (default 10 of configs/match_5v5.yaml) back to back in this one\n"
    "process, as a tournament server would, without video. In each game it kills --kills\n"
    "agent processes (default 10, SIGKILL, spread over both halves, each agent at most\n"
    "agents.restart_limit times) and freezes --stops of them (default 2, SIGSTOP, SIGCONT\n"
    "after --stop-seconds, default 3). It samples the resident memory, file descriptors and\n"
    "threads of the simulator and its agents every 0.25 s and prints one row per game.\n"
    "Game K plays seed+K-1 into DIR/game_K/ (default runs/soak-<date-time>/), on DDS domain\n"
    "D (default the first free one on this host from 0). A DIR that holds an earlier run is\n"
    "refused unless --overwrite.\n"
    "\n"
    "Checks, exit status 1 if one fails: every game finished with a complete summary.json,\n"
    "every kill was restarted, the simulator's peak memory grew < 5 % from the first game to\n"
    "the last, and it holds no more descriptors or threads after the last game than after\n"
    "the first.\n";

}  // namespace

int soak(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "overwrite"},
                    {"games", "kills", "stops", "stop-seconds", "half", "seed", "out", "domain",
                     "dds-config", "csv"});
  if (opt.help(kSoakHelp)) return 0;
  if (opt.positional().size() > 1) throw UsageError("expected at most one match config file");
  match::MatchConfig config = match::loadMatchConfig(
      findConfig(opt.positional().empty() ? "" : opt.positional()[0], "configs/match_5v5.yaml"));
  if (config.penalty_kicks > 0) throw UsageError(config.file + " is a penalty config");
  if (opt.has("half")) config.half_duration = opt.positive("half", 600);
  match::SoakOptions o;
  o.games = opt.wholeNumber("games", 10, 1, 100000);
  o.kills_per_game = opt.wholeNumber("kills", 10, 0, 10000);
  o.stops_per_game = opt.wholeNumber("stops", 2, 0, 10000);
  o.stop_seconds = opt.positive("stop-seconds", 3.0);
  // Each agent is killed at most agents.restart_limit times (more would stop the match).
  const auto agents = world::loadScenario(config.scenario).robots.size();
  if (static_cast<size_t>(o.kills_per_game) > agents * static_cast<size_t>(config.restart_limit))
    throw UsageError("--kills " + std::to_string(o.kills_per_game) + ": at most " +
                     std::to_string(agents * static_cast<size_t>(config.restart_limit)) +
                     " a game (" + std::to_string(agents) + " agents, each restarted at most " +
                     std::to_string(config.restart_limit) + " times: agents.restart_limit)");
  o.seed = opt.seed("seed", config.seed);
  o.run.out = opt.get("out", timestampedRunDir("soak-").string());
  const net::DomainClaim domain = claimDomain(opt, 0, DomainDefault::FirstFree);
  o.run.domain = domain.domain();
  o.run.dds_config = findConfig(opt.get("dds-config", ""), "configs/dds/loopback.xml");
  o.run.stop_requested = [] { return stopSignalled(); };
  stopOnSignals();
  match::prepareOut(o.run.out, opt.flag("overwrite"));
  std::printf(
      "simsoccer soak %s: %d games, %d kills and %d stops of %.1f s each per game, "
      "DDS domain %u, output %s\n",
      config.name.c_str(), o.games, o.kills_per_game, o.stops_per_game, o.stop_seconds,
      o.run.domain, o.run.out.string().c_str());
  std::fflush(stdout);
  const match::SoakResult r = match::runSoak(config, o, [](const match::SoakGame& g) {
    std::printf(
        "  game %d (seed %llu): %s %s after %.1f simulated s in %.1f s; %d kills, %d "
        "stops, %d restarts; simulator RSS peak %.1f MiB\n",
        g.index, static_cast<unsigned long long>(g.seed), g.finished ? "finished" : "NOT FINISHED",
        g.score.c_str(), g.simulated, g.wall, g.kills, g.stops, g.restarts, g.sim_peak_rss);
    std::fflush(stdout);
  });
  Table t;
  t.header = {"game",
              "seed",
              "score",
              "sim_s",
              "wall_s",
              "kills",
              "stops",
              "restarts",
              "longest_wait_s",
              "sim_rss_start_mib",
              "sim_rss_peak_mib",
              "sim_rss_end_mib",
              "sim_anon_start_mib",
              "sim_anon_end_mib",
              "heap_start_mib",
              "heap_end_mib",
              "sim_fds_start",
              "sim_fds_end",
              "sim_threads_start",
              "sim_threads_end",
              "agent_rss_start_mib",
              "agent_rss_peak_mib",
              "agent_rss_end_mib",
              "finished",
              "summary_complete"};
  for (const match::SoakGame& g : r.games)
    t.rows.push_back({std::to_string(g.index),
                      std::to_string(g.seed),
                      g.score,
                      fmt(g.simulated, 1),
                      fmt(g.wall, 1),
                      std::to_string(g.kills),
                      std::to_string(g.stops),
                      std::to_string(g.restarts),
                      fmt(g.longest_wait, 3),
                      fmt(g.sim_start.rss_mib, 1),
                      fmt(g.sim_peak_rss, 1),
                      fmt(g.sim_end.rss_mib, 1),
                      fmt(g.sim_start.anon_mib, 1),
                      fmt(g.sim_end.anon_mib, 1),
                      fmt(g.heap_start, 1),
                      fmt(g.heap_end, 1),
                      std::to_string(g.sim_start.fds),
                      std::to_string(g.sim_end.fds),
                      std::to_string(g.sim_start.threads),
                      std::to_string(g.sim_end.threads),
                      fmt(g.agent_rss_start, 1),
                      fmt(g.agent_rss_peak, 1),
                      fmt(g.agent_rss_end, 1),
                      g.finished ? "yes" : "no",
                      g.summary_complete ? "yes" : "no"});
  t.finish(
      "rss: resident memory (MiB); agents: the mean over the game's agents at its first and "
      "last sample, and the largest; end: after the game's session and agents are gone",
      opt.get("csv", ""));
  std::printf("simulator peak RSS growth from the first game to the last: %+.1f %% (limit 5 %%)\n",
              100.0 * r.rss_growth);
  for (const std::string& f : r.failures) std::printf("FAILED: %s\n", f.c_str());
  if (r.interrupted) return 130;
  std::printf(r.failures.empty() ? "soak: every check passed\n" : "soak: %zu checks failed\n",
              r.failures.size());
  return r.failures.empty() ? 0 : 1;
}

}  // namespace simsoccer::apps
