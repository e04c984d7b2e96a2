// simsoccer lola-run: starts a team's robot binary attached to one simulated
// Nao. Team code hard-codes LoLA's socket at /tmp/robocup, and a match needs
// up to 14 such binaries on one machine, so each gets a private mount
// namespace (bubblewrap, from Debian) in which that robot's socket is
// /tmp/robocup and /tmp is its own. The rest of the file system, the
// network and the user are the machine's.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "cli.hpp"
#include "simsoccer/match/match_runner.hpp"

namespace simsoccer::apps {
namespace {

const char* kHelp =
    "usage: simsoccer lola-run (--socket PATH | --robot T:P [--run DIR]) [--wait S]\n"
    "                          -- PROGRAM [ARGS...]\n"
    "\n"
    "Runs PROGRAM with a simulated robot's LoLA socket at /tmp/robocup, as on a Nao, in a\n"
    "private mount namespace (bubblewrap): its /tmp is its own, so several team binaries run\n"
    "side by side, each seeing its own robot. --robot T:P names the robot (GameController team\n"
    "number:player) of the match writing to DIR (default runs/serve; the socket is\n"
    "DIR/lola/robot_T_P.sock), --socket gives the socket itself. Waits up to S s (default\n"
    "60) for the simulator to open the socket. The program's exit status is lola-run's.\n"
    "Example, a match with two LoLA robots and two binaries:\n"
    "  simsoccer match configs/match_2v2.yaml --lola 2:1,2:2 --out runs/lola &\n"
    "  simsoccer lola-run --robot 2:1 --run runs/lola -- ./team-binary &\n"
    "  simsoccer lola-run --robot 2:2 --run runs/lola -- ./team-binary\n";

std::string findBwrap() {
  for (const char* dir : {"/usr/bin", "/bin", "/usr/local/bin"}) {
    const std::filesystem::path p = std::filesystem::path(dir) / "bwrap";
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  throw std::runtime_error("lola-run needs bubblewrap: apt-get install bubblewrap");
}

}  // namespace

int lolaRun(int argc, char** argv, int first) {
  // Everything after "--" is the program's.
  int split = argc;
  for (int i = first; i < argc; ++i)
    if (std::string(argv[i]) == "--") {
      split = i;
      break;
    }
  const Options opt(split, argv, first, {"help"}, {"socket", "robot", "run", "wait"});
  if (opt.help(kHelp)) return 0;
  opt.noPositional();
  if (split + 1 >= argc) throw UsageError("expected -- PROGRAM [ARGS...]");
  if (opt.has("socket") == opt.has("robot")) throw UsageError("give --socket or --robot");
  std::filesystem::path socket;
  if (opt.has("socket")) {
    socket = opt.get("socket", "");
  } else {
    std::vector<match::LolaPlayer> players;
    try {
      players = match::parseLolaPlayers(opt.get("robot", ""));
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--robot: ") + e.what());
    }
    if (players.size() != 1) throw UsageError("--robot: one robot");
    socket = match::lolaSocketPath(opt.get("run", "runs/serve"), players[0]);
  }
  socket = std::filesystem::absolute(socket);
  const double wait = opt.number("wait", 60.0);
  if (!(wait >= 0)) throw UsageError("--wait must be >= 0 s");
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<long>(wait * 1000));
  while (!std::filesystem::is_socket(socket)) {
    if (std::chrono::steady_clock::now() >= deadline)
      throw std::runtime_error(socket.string() + ": no LoLA socket there (is the simulator running?)");
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const std::string bwrap = findBwrap();
  std::vector<std::string> args = {bwrap,
                                   "--dev-bind", "/", "/",             // the machine as it is
                                   "--tmpfs", "/tmp",                  // but a /tmp of its own
                                   "--bind", socket.string(), "/tmp/robocup",
                                   "--chdir", std::filesystem::current_path().string(),
                                   "--unshare-pid", "--die-with-parent", "--"};
  for (int i = split + 1; i < argc; ++i) args.push_back(argv[i]);
  std::vector<char*> cargs;
  for (std::string& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  std::fflush(stdout);
  ::execv(bwrap.c_str(), cargs.data());
  throw std::runtime_error("cannot run " + bwrap);
}

}  // namespace simsoccer::apps
