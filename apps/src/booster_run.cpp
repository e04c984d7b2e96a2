// simsoccer booster-run: starts a team's Booster SDK program attached to one
// simulated robot that `serve --booster-netns` serves in a network namespace
// of its own as DDS domain 0 (what unmodified team code joins), with the Fast
// DDS profile the SDK asks for (configs/dds/booster_fastdds.xml).
#include <fcntl.h>
#include <sched.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "booster_robots.hpp"
#include "cli.hpp"
#include "simsoccer/match/match_session.hpp"

namespace simsoccer::apps {
namespace {

const char* kBoosterRunHelp =
    "usage: simsoccer booster-run --robot T:P [--profile FILE] -- PROGRAM [ARGS...]\n"
    "\n"
    "Runs PROGRAM (a team's Booster SDK client, unmodified) in the network namespace where\n"
    "`simsoccer serve SCENARIO --booster ... --booster-netns` serves robot T:P (GameController\n"
    "team number:player) as DDS domain 0, so that several such programs, each on domain 0,\n"
    "each drive their own robot; the namespace is on the field network (10.78.T.P), where the\n"
    "GameController's packets arrive. FASTRTPS_DEFAULT_PROFILES_FILE is set to\n"
    "FILE (default configs/dds/booster_fastdds.xml: the participant profile booster_dds on\n"
    "loopback) unless it is set already. Needs root (entering a network namespace); the\n"
    "program runs as this user, with this environment and file system. docs/booster.md.\n";

}  // namespace

int boosterRun(int argc, char** argv, int first) {
  int split = argc;  // everything after "--" is the program's
  for (int i = first; i < argc; ++i)
    if (std::string(argv[i]) == "--") {
      split = i;
      break;
    }
  const Options opt(split, argv, first, {"help"}, {"robot", "profile"});
  if (opt.help(kBoosterRunHelp)) return 0;
  opt.noPositional();
  if (split + 1 >= argc) throw UsageError("expected -- PROGRAM [ARGS...]");
  if (!opt.has("robot")) throw UsageError("--robot T:P is required (the robot to drive)");
  const std::string robot = opt.get("robot", "");
  // The profile before anything else: checked, and absolute (the program may change folder).
  const std::filesystem::path profile = std::filesystem::absolute(
      findConfig(opt.get("profile", ""), "configs/dds/booster_fastdds.xml"));
  if (!std::filesystem::is_regular_file(profile))
    throw UsageError("--profile " + profile.string() + ": no such file");
  std::vector<match::LolaPlayer> players;
  try {
    players = match::parseLolaPlayers(robot);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--robot: ") + e.what());
  }
  if (players.size() != 1) throw UsageError("--robot: one robot T:P");
  const std::string name =
      boosterFieldNetwork().namespaceName(players[0].team_number, players[0].player);
  const std::string path = "/run/netns/" + name;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    throw UsageError("no network namespace " + name +
                     ": is `simsoccer serve ... --booster ... --booster-netns` serving robot " +
                     robot + "?");
  if (::setns(fd, CLONE_NEWNET) != 0) {
    const int e = errno;
    ::close(fd);
    throw UsageError("cannot enter network namespace " + name + ": " + std::strerror(e) +
                     " (needs root)");
  }
  ::close(fd);
  ::setenv("FASTRTPS_DEFAULT_PROFILES_FILE", profile.c_str(), /*overwrite=*/0);
  ::execvp(argv[split + 1], argv + split + 1);
  const int e = errno;
  throw UsageError(std::string("cannot run ") + argv[split + 1] + ": " + std::strerror(e));
}

}  // namespace simsoccer::apps
