// sim::CoreClaim: a pipelined run's period thread on a CPU of its own, the
// process's other threads and its child processes on the rest, one claim per
// CPU across processes (lock files), everything as it was afterwards; and
// RunLoop using it. Real threads, a real child process, real affinity masks.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
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
    dir_ = std::filesystem::temp_directory_path() /
           ("simsoccer_cores_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  // Holds the lock file of `cpu` as another run would (-1: already held).
  int lockAsAnotherRun(int cpu) {
    const std::string path = sim::CoreClaim::lockFile(dir_, cpu).string();
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
};

TEST_F(CoreClaimTest, TheClaimingThreadGetsACpuOfItsOwnAndEverythingElseTheRest) {
  // A thread and a child process started before the claim, the thread pinned more narrowly.
  std::promise<void> release;
  std::promise<pid_t> tid_of;
  std::thread helper([&] {
    tid_of.set_value(::gettid());
    release.get_future().wait();
  });
  const pid_t helper_tid = tid_of.get_future().get();
  cpu_set_t first;
  CPU_ZERO(&first);
  CPU_SET(all_.front(), &first);
  ASSERT_EQ(sched_setaffinity(helper_tid, sizeof first, &first), 0);
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
    sim::CoreClaim claim(dir_);
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
    const sim::CoreClaim nested(dir_);
    EXPECT_FALSE(nested.held());
  }
  // All as before (the helper on its one CPU again; the child started during the claim on
  // every CPU), and the CPU free again.
  EXPECT_EQ(cpusOf(0), all_);
  EXPECT_EQ(cpusOf(helper_tid), std::vector<int>{all_.front()});
  EXPECT_EQ(cpusOf(child_before), all_);
  EXPECT_EQ(cpusOf(child_during), all_);
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

TEST_F(CoreClaimTest, ARunKeepsOffTheCpusOtherRunsHoldAndNeedsTwoFree) {
  // Other runs hold the highest k CPUs: this one claims the highest free one and keeps the
  // rest of the free ones for its other threads, while at least two are free.
  std::vector<int> held;
  for (size_t k = 0; k < all_.size(); ++k) {
    const std::vector<int> free(all_.begin(), all_.end() - static_cast<long>(k));
    {
      const sim::CoreClaim claim(dir_);
      if (free.size() >= 2) {
        ASSERT_TRUE(claim.held()) << k << " held by others";
        EXPECT_EQ(claim.cpu(), free.back());
        EXPECT_EQ(claim.otherCpus(), without(free, free.back()));
        EXPECT_EQ(cpusOf(0), std::vector<int>{free.back()});
      } else {
        EXPECT_FALSE(claim.held());  // one CPU free: nothing left for the rest
        EXPECT_EQ(cpusOf(0), all_);  // placement left to the scheduler
      }
    }
    EXPECT_EQ(cpusOf(0), all_);
    held.push_back(lockAsAnotherRun(all_[all_.size() - 1 - k]));
    ASSERT_GE(held.back(), 0);
  }
  for (const int fd : held) ::close(fd);
}

TEST_F(CoreClaimTest, BalanceLendsTheClaimedCpuToAChildOnlyWhileNothingElseRunsThere) {
  // Two CPUs for this test (so the rest is one CPU whatever the machine) and two children
  // busy on the rest while the claiming thread sleeps. With another thread busy on the
  // claimed CPU nothing is lent; once it stops, one child moves over as a guest, at
  // SCHED_IDLE, and stays one, the other stays. Afterwards both as before the claim.
  cpu_set_t two;
  CPU_ZERO(&two);
  CPU_SET(all_[0], &two);
  CPU_SET(all_[1], &two);
  ASSERT_EQ(sched_setaffinity(0, sizeof two, &two), 0);
  const std::vector<int> both{all_[0], all_[1]};
  const auto spawnBusy = [] {
    pid_t pid = -1;
    char sh[] = "/bin/sh", c[] = "-c", loop[] = "while :; do :; done";
    char* argv[] = {sh, c, loop, nullptr};
    EXPECT_EQ(posix_spawn(&pid, argv[0], nullptr, nullptr, argv, environ), 0);
    return pid;
  };
  std::vector<pid_t> children;
  {
    sim::CoreClaim claim(dir_);
    ASSERT_TRUE(claim.held());
    for (int i = 0; i < 2; ++i)
      sim::CoreClaim::spawnOnOtherCpus([&] { children.push_back(spawnBusy()); });
    EXPECT_EQ(claim.balance(), 0u);  // the first call only measures
    // Another program on the claimed CPU (here a thread of this one, not the period thread).
    std::atomic<bool> stop{false};
    std::thread other([&] {
      cpu_set_t mine;
      CPU_ZERO(&mine);
      CPU_SET(claim.cpu(), &mine);
      (void)sched_setaffinity(0, sizeof mine, &mine);
      while (!stop.load(std::memory_order_relaxed)) {
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(claim.balance(), 0u);
    EXPECT_TRUE(claim.shared());
    EXPECT_GT(claim.foreignShare(), 0.3);
    stop = true;
    other.join();
    claim.balance();  // a window of its own from here
    const auto isGuest = [&](pid_t pid) {
      return cpusOf(pid) == std::vector<int>{claim.cpu()} && sched_getscheduler(pid) == SCHED_IDLE;
    };
    const auto isRest = [&](pid_t pid) {
      return cpusOf(pid) == claim.otherCpus() && sched_getscheduler(pid) == SCHED_OTHER;
    };
    // The tests beside this one may use the claimed CPU too: windows they spoil lend nothing.
    pid_t guest = -1;
    for (int window = 0; window < 20 && guest < 0; ++window) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      const size_t n = claim.balance();
      if (claim.shared()) {
        EXPECT_EQ(n, 0u);
        continue;
      }
      ASSERT_EQ(n, 1u);
      guest = isGuest(children[0]) ? children[0] : children[1];
    }
    if (guest < 0) {
      for (const pid_t pid : children) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, nullptr, 0);
      }
      GTEST_SKIP() << "other programs used the claimed CPU in every window";
    }
    const pid_t rest = guest == children[0] ? children[1] : children[0];
    EXPECT_TRUE(isGuest(guest));
    EXPECT_TRUE(isRest(rest));
    // Each now alone on a CPU: the guest still relieves the busier side.
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const size_t n = claim.balance();
    if (!claim.shared()) {
      EXPECT_EQ(n, 1u);
      EXPECT_TRUE(isGuest(guest));
      EXPECT_TRUE(isRest(rest));
    }
  }
  for (const pid_t pid : children) {
    EXPECT_EQ(cpusOf(pid), both);
    EXPECT_EQ(sched_getscheduler(pid), SCHED_OTHER);
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
  }
  cpu_set_t all;
  CPU_ZERO(&all);
  for (const int cpu : all_) CPU_SET(cpu, &all);
  EXPECT_EQ(sched_setaffinity(0, sizeof all, &all), 0);
}

// Records, in each observe stage, the CPUs the period thread may use and the solver
// threads given work.
class PeriodProbe : public sim::CommandSource {
 public:
  void observe(const sim::Observation& o) override {
    cpus.push_back(cpusOf(0));
    solver_threads.push_back(o.world->physics().activeSolverThreads());
    batches = std::max(batches, o.world->physics().lastStepSolverBatches());
  }
  void collect(uint64_t, sim::CommandGate&, std::span<sim::CommandSlot>) override {}
  std::vector<std::vector<int>> cpus;
  std::vector<int> solver_threads;
  int batches = 0;
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
    PeriodProbe probe;
    simulation.addSource(probe);
    const sim::RunStats run = sim::RunLoop(simulation, sim::Pacing::Lockstep).run(50);
    // The claim uses the default lock folder, shared with the runs of tests beside this
    // one: it may find none free.
    if (mode == sim::Mode::Serial || !own_core) {
      EXPECT_EQ(run.period_cpu, -1);
    }
    const bool claimed = run.period_cpu >= 0;
    for (const auto& cpus : probe.cpus)
      EXPECT_EQ(cpus, claimed ? std::vector<int>{run.period_cpu} : all_);
    for (const int n : probe.solver_threads) EXPECT_EQ(n, claimed ? 1 : 2);
    EXPECT_GE(probe.batches, 2);  // so two solver threads have work to share
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
