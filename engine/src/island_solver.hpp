// Solving the simulation islands of a btMultiBodyDynamicsWorld on several
// threads (engine-internal).
//
// An island is a set of bodies that touch or are jointed (a robot, robots in
// contact, the ball against a foot); islands share no body. Bullet solves
// them in batches: it appends island after island to a batch until the batch
// holds more than m_minimumSolverBatchSize manifolds and constraints, solves
// it, and starts the next. Here the batches are formed the same way, then
// solved side by side on several threads, each with its own solver. A batch
// reads and writes only its own bodies, so the result is the same, bit for
// bit, whatever the number of threads, and the same as Bullet's own loop
// with the same solver (the tests hold it to both). (Solving
// each island on its own would not be: a batch iterates until all its rows
// have converged, which differs in the last bits from stopping each island
// when its own rows have.)
#pragma once

#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>

#include <algorithm>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace simsoccer::engine {

// Threads that run one job together: run() calls job(i) on every thread i
// (0 is the caller's) and returns when all have finished; an exception thrown
// by the job on any thread is rethrown there, after all have finished.
class WorkerThreads {
 public:
  explicit WorkerThreads(int threads);  // threads >= 1; threads - 1 are started
  ~WorkerThreads();
  WorkerThreads(const WorkerThreads&) = delete;
  WorkerThreads& operator=(const WorkerThreads&) = delete;
  int count() const { return static_cast<int>(workers_.size()) + 1; }
  void run(const std::function<void(int)>& job);

 private:
  void loop(int index);
  void stop();
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, finished_;
  const std::function<void(int)>* job_ = nullptr;
  uint64_t generation_ = 0;
  int running_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;  // the first a worker threw in this run
};

// The island callback: collects the islands while Bullet's island manager
// builds them, then solves them on the threads. It relies on batches sharing
// no body that the solver writes: true for dynamic rigid bodies and floating-
// base multibodies (each in one island), which is all the engine creates; a
// kinematic body or a fixed-base multibody touching two batches would be
// written by two threads (their solver ids). PhysicsWorld uses Bullet's own
// loop when the solver randomises its order or islands are not split (island
// ids are then >= 0 here).
class ParallelIslandSolver : public btSimulationIslandManager::IslandCallback {
 public:
  // make_solver: one constraint solver per thread.
  ParallelIslandSolver(
      int threads,
      const std::function<std::unique_ptr<btMultiBodyConstraintSolver>()>& make_solver);

  // Before the islands are built: the solver settings and the world's
  // constraints, sorted by island (as Bullet sorts them for its own callback).
  // `multibody_islands` (may be null): the island of each multibody
  // constraint, as they are sorted (saves asking each constraint again).
  void setup(const btContactSolverInfo& info, btTypedConstraint** constraints, int num_constraints,
             btMultiBodyConstraint** multibody_constraints, int num_multibody_constraints,
             const int* multibody_islands = nullptr);
  void processIsland(btCollisionObject** bodies, int num_bodies, btPersistentManifold** manifolds,
                     int num_manifolds, int island_id) override;
  // Solves every batch collected since setup(). `prologue` (if set) runs on
  // the batch's thread just before it is solved, with the batch's bodies and
  // the thread's index (0 .. threads - 1).
  using Prologue = std::function<void(btCollisionObject** bodies, int num_bodies, int thread)>;
  void solve(btIDebugDraw* debug_draw, btDispatcher* dispatcher,
             const Prologue* prologue = nullptr);
  int threadCount() const { return threads_.count(); }
  // Solves on the first `n` threads only (1 .. threadCount(); the others
  // idle): the same result for any number.
  void setActiveThreads(int n) { active_ = std::clamp(n, 1, threadCount()); }
  int activeThreads() const { return active_; }
  void clear() { batch_count_ = 0; }  // a step solved without it
  int batchCount() const { return static_cast<int>(batch_count_); }

 private:
  struct Batch {
    btAlignedObjectArray<btCollisionObject*> bodies;
    btAlignedObjectArray<btPersistentManifold*> manifolds;
    btAlignedObjectArray<btTypedConstraint*> constraints;
    btAlignedObjectArray<btMultiBodyConstraint*> multibody_constraints;
    long cost = 0;  // about the number of solver rows
  };
  Batch& openBatch();  // the batch islands are appended to
  void solveBatch(int thread, Batch& batch);

  std::vector<std::unique_ptr<btMultiBodyConstraintSolver>> solvers_;  // one per thread
  std::vector<Batch> batches_;                                         // reused step to step
  size_t batch_count_ = 0;  // in use this step; the last one may still be open
  bool batch_open_ = false;
  std::vector<std::vector<size_t>> shares_;  // per thread: its batches
  std::vector<size_t> order_;                // batches, largest first
  std::vector<long> load_;                   // per thread: the cost of its batches
  std::function<void(int)> job_;             // thread t solves shares_[t]
  int active_ = 1;                           // threads given batches
  WorkerThreads threads_;                    // last: stopped before the rest goes
  btTypedConstraint** constraints_ = nullptr;
  int num_constraints_ = 0;
  btMultiBodyConstraint** multibody_constraints_ = nullptr;
  int num_multibody_constraints_ = 0;
  const int* multibody_islands_ = nullptr;
  const btContactSolverInfo* info_ = nullptr;
  btIDebugDraw* debug_draw_ = nullptr;
  btDispatcher* dispatcher_ = nullptr;
  const Prologue* prologue_ = nullptr;
};

}  // namespace simsoccer::engine
