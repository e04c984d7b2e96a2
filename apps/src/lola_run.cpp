// simsoccer lola-run: starts a team's robot binary attached to one simulated
// Nao. Team code hard-codes LoLA's socket at /tmp/robocup, and a match needs
// up to 14 such binaries on one machine, so each gets a private mount
// namespace (bubblewrap, from Debian) with a /tmp of its own in which that
// robot's socket is /tmp/robocup (the program's folders under the machine's
// /tmp are bound back). The rest of the file system, the network (unless
// --net) and the user are the machine's.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "cli.hpp"
#include "simsoccer/lola/field_network.hpp"
#include "simsoccer/match/lola_robots.hpp"

extern char** environ;

namespace simsoccer::apps {
namespace {

const char* kLolaRunHelp =
    "usage: simsoccer lola-run (--socket PATH | --robot T:P [--run DIR]) [--wait S]\n"
    "                          [--net [--bridge NAME] [--prefix A.B]] -- PROGRAM [ARGS...]\n"
    "\n"
    "Runs PROGRAM with a simulated robot's LoLA socket at /tmp/robocup, as on a Nao, in a\n"
    "private mount namespace (bubblewrap) with a /tmp of its own, so several team binaries\n"
    "run side by side, each seeing its own robot there (the working directory and the folders\n"
    "of the program and its file arguments under /tmp stay visible). --robot T:P names the robot "
    "(GameController team\n"
    "number:player) of the match writing to DIR (default runs/serve; the socket is\n"
    "DIR/lola/robot_T_P.sock), --socket gives the socket itself. Waits up to S s (default\n"
    "60) for the simulator to open the socket. The program's exit status is lola-run's.\n"
    "--net (root; needs --robot, and the simulator started with --lola-net): the program also\n"
    "gets a network namespace of its own on the field network, address PREFIX.T.P (default\n"
    "10.77.T.P, as 10.0.T.P on a field): it binds 3838 and 10000+T for itself, receives the\n"
    "simulator's GameController packets, sends status to PREFIX.0.1:3939 and broadcasts team\n"
    "messages to its teammates, unmodified.\n"
    "Example, a match with two LoLA robots and two binaries:\n"
    "  simsoccer match configs/match_2v2.yaml --lola 2:1,2:2 --out runs/lola &\n"
    "  simsoccer lola-run --robot 2:1 --run runs/lola -- ./team-binary &\n"
    "  simsoccer lola-run --robot 2:2 --run runs/lola -- ./team-binary\n";

volatile std::sig_atomic_t g_child = -1;  // a pid fits
void forward(int signal) {
  if (g_child > 0) ::kill(static_cast<pid_t>(g_child), signal);
}

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
  const Options opt(split, argv, first, {"help", "net"},
                    {"socket", "robot", "run", "wait", "bridge", "prefix"});
  if (opt.help(kLolaRunHelp)) return 0;
  opt.noPositional();
  if (split + 1 >= argc) throw UsageError("expected -- PROGRAM [ARGS...]");
  if (!opt.has("socket") && !opt.has("robot")) throw UsageError("give --socket or --robot");
  if (opt.has("socket") && opt.has("robot") && !opt.flag("net"))
    throw UsageError(
        "--socket and --robot exclude each other (--robot finds the socket; with "
        "--net it also names the robot's address)");
  if (opt.has("socket") && opt.get("socket", "").empty()) throw UsageError("--socket: empty path");
  if (!opt.flag("net") && (opt.has("prefix") || opt.has("bridge")))
    throw UsageError("--prefix and --bridge go with --net");
  if (opt.flag("net") && !opt.has("robot"))
    throw UsageError("--net: give --robot T:P (its address)");
  std::vector<match::LolaPlayer> players;
  if (opt.has("robot")) {
    try {
      players = match::parseLolaPlayers(opt.get("robot", ""));
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--robot: ") + e.what());
    }
    if (players.size() != 1) throw UsageError("--robot: one robot");
  }
  std::filesystem::path socket =
      opt.has("socket") ? std::filesystem::path(opt.get("socket", ""))
                        : match::lolaSocketPath(opt.get("run", "runs/serve"), players[0]);
  socket = std::filesystem::absolute(socket);
  const double wait = opt.number("wait", 60.0);
  if (!(wait >= 0 && wait <= 86400)) throw UsageError("--wait must be 0 to 86400 s");
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<long>(wait * 1000));
  while (!std::filesystem::is_socket(socket)) {
    if (std::chrono::steady_clock::now() >= deadline)
      throw std::runtime_error(socket.string() +
                               ": no LoLA socket there (is the simulator running?)");
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const std::string bwrap = findBwrap();
  std::vector<std::string> args;
  std::unique_ptr<lola::RobotNamespace> netns;
  if (opt.flag("net")) {
    lola::FieldNetwork net;
    net.bridge = opt.get("bridge", net.bridge);
    net.prefix = opt.get("prefix", net.prefix);
    unsigned a = 256, b = 256;
    char rest = 0;
    if (std::sscanf(net.prefix.c_str(), "%u.%u%c", &a, &b, &rest) != 2 || a > 255 || b > 255)
      throw UsageError("--prefix " + net.prefix + ": the network's first two numbers, A.B");
    if (!std::filesystem::exists("/sys/class/net/" + net.bridge))
      throw std::runtime_error("no field network '" + net.bridge +
                               "': start the simulator with --lola-net first");
    netns = std::make_unique<lola::RobotNamespace>(net, players[0].team_number, players[0].player);
    std::printf("lola-run: %s in network namespace %s\n", netns->address().c_str(),
                netns->name().c_str());
    args = {"ip", "netns", "exec", netns->name()};
  }
  // The machine as it is, but a /tmp of its own (team code keeps lock, pid
  // and log files there) with the robot's socket at /tmp/robocup. What the
  // program needs from the machine's /tmp is bound back: the working
  // directory, and the folder of the program and of every argument that
  // names a file or folder there.
  std::vector<std::string> sandbox = {bwrap, "--dev-bind", "/", "/", "--tmpfs", "/tmp"};
  std::vector<std::filesystem::path> keep = {std::filesystem::current_path()};
  for (int i = split + 1; i < argc; ++i) {
    std::error_code ec;
    const auto p = std::filesystem::absolute(argv[i], ec);
    if (!ec && std::filesystem::exists(p, ec))
      keep.push_back(std::filesystem::is_directory(p, ec) ? p : p.parent_path());
  }
  for (const auto& k : keep) {
    const std::string s = k.lexically_normal().string();
    if (s.rfind("/tmp/", 0) == 0 && s != "/tmp/robocup")
      sandbox.insert(sandbox.end(), {"--bind", s, s});
  }
  sandbox.insert(sandbox.end(), {"--bind", socket.string(), "/tmp/robocup", "--chdir",
                                 std::filesystem::current_path().string(), "--unshare-pid",
                                 "--die-with-parent", "--"});
  args.insert(args.end(), sandbox.begin(), sandbox.end());
  for (int i = split + 1; i < argc; ++i) args.push_back(argv[i]);
  std::vector<char*> cargs;
  for (std::string& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  std::fflush(stdout);
  if (!netns) {
    ::execvp(cargs[0], cargs.data());
    throw std::runtime_error("cannot run " + args[0]);
  }
  // With a namespace lola-run stays to remove it when the program ends, and
  // passes the signals that end it on. They are blocked until the handler
  // knows the child, so none can end lola-run before (and leave the namespace).
  sigset_t ending, before;
  sigemptyset(&ending);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&ending, s);
  ::sigprocmask(SIG_BLOCK, &ending, &before);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setsigmask(&attributes, &before);  // the child starts unblocked
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = -1;
  const int spawned = posix_spawnp(&pid, cargs[0], nullptr, &attributes, cargs.data(), environ);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) {
    ::sigprocmask(SIG_SETMASK, &before, nullptr);
    throw std::runtime_error("cannot run " + args[0]);
  }
  g_child = pid;
  for (int s : {SIGINT, SIGTERM, SIGHUP}) std::signal(s, forward);
  ::sigprocmask(SIG_SETMASK, &before, nullptr);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  g_child = -1;
  netns.reset();
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace simsoccer::apps
