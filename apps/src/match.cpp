// simsoccer match / penalty: the main job. Parses the options, builds the
// session and hands it to the match runner (simsoccer/match), then prints.
#include <algorithm>
#include <cstdio>

#include "cli.hpp"
#include "domain_option.hpp"
#include "help_texts.hpp"
#include "lola_option.hpp"
#include "simsoccer/match/match_runner.hpp"
#include "simsoccer/match/outputs.hpp"
#include "simsoccer/net/credentials.hpp"

namespace simsoccer::apps {
namespace {

using match::MatchConfig;
using match::MatchSession;
using match::RunOptions;

RunOptions runOptions(const Options& opt, const MatchConfig& c) {
  RunOptions o;
  o.out = opt.has("out") ? std::filesystem::path(opt.get("out", "")) : timestampedRunDir("");
  o.seed = opt.seed("seed", c.seed);
  o.overwrite = opt.flag("overwrite");
  o.dds_config = findConfig(opt.get("dds-config", ""), "configs/dds/loopback.xml");
  if (!std::filesystem::is_regular_file(o.dds_config))
    throw UsageError(opt.has("dds-config")
                         ? "--dds-config " + o.dds_config.string() + ": no such file"
                         : "the default DDS configuration " + o.dds_config.string() +
                               " is missing (give one with --dds-config)");
  o.stop_requested = [] { return stopSignalled(); };
  o.notice = [](const std::string& line) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  stopOnSignals();
  return o;
}

// The live status line: half, clock, state, score, simulated time, RTF, ETA.
void printStatus(const MatchSession& session, double wall) {
  const auto& g = session.game();
  const double t = session.world().time();
  const double rtf = t / std::max(1e-6, wall);
  const double half = g.rules().half_duration;
  const double left_sim =
      std::max(0.0, g.secondsRemaining() + (g.half() == referee::Half::First ? half : 0.0));
  std::printf("\r  %s half  %02d:%02d  %-8s  %d:%d   sim %6.1f s  RTF %4.2f  ETA %4.0f s   ",
              g.half() == referee::Half::First
                  ? "1st"
                  : (g.half() == referee::Half::Second ? "2nd" : "pso"),
              static_cast<int>(g.secondsRemaining()) / 60,
              static_cast<int>(g.secondsRemaining()) % 60, referee::stateName(g.state()),
              g.score(0), g.score(1), t, rtf, left_sim / std::max(rtf, 1e-3));
  std::fflush(stdout);
}

}  // namespace

int match(int argc, char** argv, int first) {
  const Options opt(
      argc, argv, first,
      {"help", "realtime", "external-agents", "no-video", "quiet", "lola-net", "overwrite"},
      {"out", "seed", "half", "domain", "dds-config", "max-seconds", "lockstep-timeout", "mode",
       "lola", "external-gc", "secure"});
  char help[4096];
  std::snprintf(help, sizeof help, kMatchHelp, sim::modeName(sim::kDefaultMode));
  if (opt.help(help)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one match config file");
  MatchConfig config = match::loadMatchConfig(opt.positional()[0]);
  if (config.penalty_kicks > 0)
    throw UsageError(config.file + " is a penalty config: use `simsoccer penalty`");
  if (opt.has("half")) {
    const double h = opt.number("half", 0);
    if (!(h > 0)) throw UsageError("--half must be > 0 s");
    config.half_duration = h;
  }
  if (opt.has("lockstep-timeout")) {
    const double t = opt.number("lockstep-timeout", 0);
    if (!(t > 0)) throw UsageError("--lockstep-timeout must be > 0 s");
    config.command_timeout = t;
  }
  addLolaRobots(opt, config);
  if (opt.has("external-gc"))
    config.external_gc_port = static_cast<uint16_t>(opt.wholeNumber("external-gc", 3838, 1, 65535));
  if (config.external_gc_port == 3939)
    throw UsageError(
        "--external-gc 3939: the GameController's own port (it hears the robots "
        "there); its packets come on 3838");
  RunOptions o = runOptions(opt, config);
  o.realtime = opt.flag("realtime") || config.external_gc_port.has_value();
  o.external = opt.flag("external-agents");
  const uint32_t secure_max = net::CredentialsOptions{}.domain_max;
  if (opt.has("secure") && opt.domain("domain", 0) > secure_max)
    throw UsageError("--secure: the credentials cover DDS domains 0 to " +
                     std::to_string(secure_max) + ", not " +
                     std::to_string(opt.domain("domain", 0)));
  // Agents started elsewhere are told the domain; this run's own find theirs.
  const net::DomainClaim domain =
      claimDomain(opt, 0, o.external ? DomainDefault::Fixed : DomainDefault::FirstFree,
                  opt.has("secure") ? secure_max : 232);
  o.domain = domain.domain();
  if (opt.has("secure")) {
    if (opt.has("dds-config"))
      throw UsageError(
          "--secure and --dds-config exclude each other (the credentials' ID.xml "
          "files are the Cyclone configurations)");
    o.secure = opt.get("secure", "");
    for (const std::string& id : net::credentialIdentities())
      if (!std::filesystem::is_regular_file(net::credentialConfig(o.secure, id)))
        throw UsageError("--secure " + o.secure.string() + ": no " + id + ".xml" +
                         " (make the folder with `simsoccer credentials DIR`)");
    net::checkMatchCredentials(o.secure);
  }
  o.video = config.video.enabled && !opt.flag("no-video");
  o.max_seconds = opt.nonNegative("max-seconds", 0);
  try {
    o.mode = sim::parseMode(opt.get("mode", sim::modeName(sim::defaultMode(!o.realtime))));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--mode: ") + e.what());
  }
  const bool tty = !opt.flag("quiet") && isatty(STDOUT_FILENO);
  if (tty) o.progress = printStatus;
  MatchSession session(config, o.seed);  // (a bad --lola robot stops here, nothing written)
  match::prepareOut(o.out, o.overwrite);
  std::printf(
      "simsoccer match %s: %zu robots, seed %llu, %s, %s periods, DDS domain %u, output %s\n",
      config.name.c_str(), session.world().robotCount(), static_cast<unsigned long long>(o.seed),
      o.realtime ? "real time" : "lockstep", sim::modeName(*o.mode), o.domain,
      o.out.string().c_str());
  std::fflush(stdout);
  const match::RunResult r = match::playMatch(session, o);
  if (tty) std::printf("\n");
  const auto& g = session.game();
  std::printf("%s: %d:%d after %.1f simulated s in %.1f s (real-time factor %.2f); log %.1f MB\n",
              r.interrupted ? "interrupted" : (r.aborted ? "stopped" : "final"), g.score(0),
              g.score(1), session.world().time(), r.wall,
              session.world().time() / std::max(r.wall, 1e-9),
              static_cast<double>(r.log_bytes) / 1e6);
  if (r.aborted) std::printf("stopped: %s\n", r.abort_reason.c_str());
  for (const auto& goal : session.goals()) {
    std::string how = goal.own_goal ? " (own goal)" : "";
    if (goal.deflected_by > 0)
      how = " (in off team " + std::to_string(1 - goal.team) + " player " +
            std::to_string(goal.deflected_by) + ")";
    std::printf("  goal %7.1f s  team %d  player %d%s\n", goal.time, goal.team, goal.scorer,
                how.c_str());
  }
  if (r.video_frames > 0)
    std::printf("video: %s, %d frames\n", (o.out / "match.mp4").string().c_str(), r.video_frames);
  for (const match::LolaResult& l : r.lola)
    std::printf("LoLA robot %d:%d: %llu sessions, %llu maps, %llu missed, %llu faults\n",
                l.player.team_number, l.player.player,
                static_cast<unsigned long long>(l.stats.sessions),
                static_cast<unsigned long long>(l.stats.maps),
                static_cast<unsigned long long>(l.stats.missed),
                static_cast<unsigned long long>(l.stats.bad_maps + l.stats.stream_errors +
                                                l.stats.refused));
  std::printf("wrote %s\n", (o.out / "summary.json").string().c_str());
  return r.aborted ? 3 : (r.interrupted ? 130 : 0);
}

int penalty(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "quiet", "overwrite"},
                    {"kicks", "out", "seed", "video-kicks", "domain", "dds-config"});
  if (opt.help(kPenaltyHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one penalty config file");
  MatchConfig config = match::loadMatchConfig(opt.positional()[0]);
  if (config.penalty_kicks == 0)
    throw UsageError(config.file + " is not a penalty config (`penalty: NAME`)");
  const int kicks = opt.wholeNumber("kicks", config.penalty_kicks, 1, 100000);
  if (kicks < 1) throw UsageError("--kicks must be >= 1");
  const int video_kicks = opt.wholeNumber("video-kicks", 3, 0, 100000);
  RunOptions o = runOptions(opt, config);
  const net::DomainClaim domain = claimDomain(opt, 0, DomainDefault::FirstFree);
  o.domain = domain.domain();
  const match::PenaltyResult r = match::playPenalties(
      config, o, kicks, video_kicks, [](int kick, uint64_t seed, const std::string& outcome) {
        std::printf("  kick %2d (seed %llu): %s\n", kick, static_cast<unsigned long long>(seed),
                    outcome.c_str());
        std::fflush(stdout);
      });
  const int n = static_cast<int>(r.outcomes.size());
  const match::Proportion p = match::wilsonInterval(r.goals, n);
  std::printf(
      "penalties: %d kicks, %d goals: scoring rate %.2f (95%% CI %.2f..%.2f); saved %d, missed %d, "
      "timeout %d\n",
      n, r.goals, p.rate, p.low, p.high, r.saved, r.missed, r.timeout);
  for (const auto& v : r.videos) std::printf("video: %s\n", v.string().c_str());
  std::printf("wrote %s\n", (o.out / "penalty.json").string().c_str());
  return r.interrupted ? 130 : 0;
}

}  // namespace simsoccer::apps
