// sim::CoreClaim: a pipelined run's period thread on a CPU of its own, the
// process's other threads and its child processes on the rest, one claim per
// CPU across processes (lock files), everything as it was afterwards; and
// RunLoop using it. Real threads, a real child process, real affinity masks.
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "simsoccer/sim/cores.hpp"
#include "simsoccer/sim/run_loop.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

std::vector<int> cpusOf(pid_t tid) {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> cpus;
  if (sched_getaffinity(tid, sizeof set, &set) != 0) return cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  return cpus;
}

std::vector<int> without(std::vector<int> cpus, int cpu) {
  std::erase(cpus, cpu);
  return cpus;
}

// Lock files in a folder of this test's own: runs beside it (other tests'
// pipelined runs) claim from theirs.
class CoreClaimTest : public ::testing::Test {
 protected:
  void SetUp() override {
    all_ = cpusOf(0);
    if (all_.size() < 2) GTEST_SKIP() << "this process may use " << all_.size() << " CPU";
    const char* before = std::getenv("XDG_RUNTIME_DIR");
    if (before) saved_ = before;
    had_ = before != nullptr;
    dir_ = std::filesystem::temp_directory_path() /
           ("simsoccer_cores_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
    ::setenv("XDG_RUNTIME_DIR", dir_.c_str(), 1);
  }
  void TearDown() override {
    if (had_)
      ::setenv("XDG_RUNTIME_DIR", saved_.c_str(), 1);
    else
      ::unsetenv("XDG_RUNTIME_DIR");
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  // Holds the lock file of `cpu` as another run would (-1: already held).
  int lockAsAnotherRun(int cpu) {
    const std::string path = (dir_ / ("simsoccer-cpu" + std::to_string(cpu) + ".lock")).string();
    const int fd = ::open(path.c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) return -1;
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      return -1;
    }
    return fd;
  }

  std::vector<int> all_;
  std::filesystem::path dir_;
  std::string saved_;
  bool had_ = false;
};

TEST_F(CoreClaimTest, TheClaimingThreadGetsACpuOfItsOwnAndEverythingElseTheRest) {
  // A thread and a child process started before the claim.
  std::promise<void> release;
  std::promise<pid_t> tid_of;
  std::thread helper([&] {
    tid_of.set_value(::gettid());
    release.get_future().wait();
  });
  const pid_t helper_tid = tid_of.get_future().get();
  const auto spawnSleep = [] {
    pid_t pid = -1;
    char sleep_path[] = "/bin/sleep", seconds[] = "30";
    char* argv[] = {sleep_path, seconds, nullptr};
    EXPECT_EQ(posix_spawn(&pid, argv[0], nullptr, nullptr, argv, environ), 0);
    return pid;
  };
  const pid_t child_before = spawnSleep();
  pid_t child_during = -1;
  {
    sim::CoreClaim claim;
    ASSERT_TRUE(claim.held());
    EXPECT_EQ(claim.cpu(), all_.back());  // the highest, no other run holding one
    const std::vector<int> others = without(all_, claim.cpu());
    EXPECT_EQ(claim.otherCpus(), others);
    EXPECT_EQ(cpusOf(0), std::vector<int>{claim.cpu()});
    EXPECT_EQ(cpusOf(helper_tid), others);
    EXPECT_EQ(cpusOf(child_before), others);
    // A process started during the claim starts on the others; the caller keeps its CPU.
    sim::CoreClaim::spawnOnOtherCpus([&] { child_during = spawnSleep(); });
    EXPECT_EQ(cpusOf(child_during), others);
    EXPECT_EQ(cpusOf(0), std::vector<int>{claim.cpu()});
    // Another run cannot take the same CPU; a second claim in this process takes none.
    EXPECT_EQ(lockAsAnotherRun(claim.cpu()), -1);
    const sim::CoreClaim nested;
    EXPECT_FALSE(nested.held());
  }
  // All as before, and the CPU free again.
  EXPECT_EQ(cpusOf(0), all_);
  EXPECT_EQ(cpusOf(helper_tid), all_);
  EXPECT_EQ(cpusOf(child_before), all_);
  const int fd = lockAsAnotherRun(all_.back());
  EXPECT_GE(fd, 0);
  if (fd >= 0) ::close(fd);
  for (const pid_t pid : {child_before, child_during}) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
  }
  release.set_value();
  helper.join();
}

TEST_F(CoreClaimTest, ARunFindingItsCpuTakenClaimsAnotherAndWithNoneFreeClaimsNothing) {
  std::vector<int> held;
  for (size_t k = 0; k + 1 < all_.size(); ++k) {
    const int cpu = all_[all_.size() - 1 - k];
    const int fd = lockAsAnotherRun(cpu);
    ASSERT_GE(fd, 0);
    held.push_back(fd);
    const sim::CoreClaim claim;  // the highest CPU no one holds
    ASSERT_TRUE(claim.held());
    EXPECT_EQ(claim.cpu(), all_[all_.size() - 2 - k]);
    EXPECT_EQ(claim.otherCpus(), without(all_, claim.cpu()));
  }
  held.push_back(lockAsAnotherRun(all_.front()));
  ASSERT_GE(held.back(), 0);
  {
    const sim::CoreClaim claim;  // every CPU held by another run
    EXPECT_FALSE(claim.held());
    EXPECT_EQ(cpusOf(0), all_);  // placement left to the scheduler
  }
  for (const int fd : held) ::close(fd);
}

// Records the CPUs the period thread may use in each observe stage.
class AffinityProbe : public sim::CommandSource {
 public:
  void observe(const sim::Observation&) override { seen.push_back(cpusOf(0)); }
  void collect(uint64_t, sim::CommandGate&, std::span<sim::CommandSlot>) override {}
  std::vector<std::vector<int>> seen;
};

TEST_F(CoreClaimTest, APipelinedRunStepsOnItsOwnCpuWithOneSolverThreadAndTheSameResult) {
  const auto run = [&](sim::Mode mode, bool own_core) {
    world::Scenario s = test::scenario(4);
    s.physics.threads = 2;
    world::World w(s);
    sim::SimulationConfig c;
    c.mode = mode;
    c.own_core = own_core;
    sim::Simulation simulation(w, c);
    AffinityProbe probe;
    simulation.addSource(probe);
    sim::RunLoop(simulation, sim::Pacing::Lockstep).run(50);
    const bool claimed = mode == sim::Mode::Pipelined && own_core;
    for (const auto& cpus : probe.seen)
      EXPECT_EQ(cpus, claimed ? std::vector<int>{all_.back()} : all_);
    // Afterwards the thread and the solver as they were.
    EXPECT_EQ(cpusOf(0), all_);
    EXPECT_EQ(w.physics().activeSolverThreads(), 2);
    return w.stateHash();
  };
  const uint64_t own = run(sim::Mode::Pipelined, true);
  EXPECT_EQ(own, run(sim::Mode::Pipelined, false));
  run(sim::Mode::Serial, true);  // a serial run claims nothing
}

}  // namespace
