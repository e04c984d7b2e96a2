#include "island_solver.hpp"

#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/ConstraintSolver/btTypedConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraint.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace simsoccer::engine {

WorkerThreads::WorkerThreads(int threads) {
  if (threads < 1) throw std::invalid_argument("WorkerThreads: threads must be >= 1");
  try {
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { loop(i); });
  } catch (...) {  // a thread could not start: stop those that did
    stop();
    throw;
  }
}

WorkerThreads::~WorkerThreads() {
  stop();
}

void WorkerThreads::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& t : workers_)
    if (t.joinable()) t.join();
}

void WorkerThreads::run(const std::function<void(int)>& job) {
  if (workers_.empty()) {
    job(0);
    return;
  }
  {
    std::lock_guard lock(mutex_);
    job_ = &job;
    running_ = static_cast<int>(workers_.size());
    error_ = nullptr;
    ++generation_;
  }
  start_.notify_all();
  std::exception_ptr own;
  try {
    job(0);
  } catch (...) {
    own = std::current_exception();
  }
  // Always wait: the workers use what the job refers to.
  std::unique_lock lock(mutex_);
  finished_.wait(lock, [&] { return running_ == 0; });
  job_ = nullptr;
  if (own) std::rethrow_exception(own);
  if (error_) std::rethrow_exception(error_);
}

void WorkerThreads::loop(int index) {
  uint64_t seen = 0;
  for (;;) {
    const std::function<void(int)>* job = nullptr;
    {
      std::unique_lock lock(mutex_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      job = job_;
    }
    std::exception_ptr error;
    try {
      (*job)(index);
    } catch (...) {  // handed to run()'s caller
      error = std::current_exception();
    }
    bool last = false;
    {
      std::lock_guard lock(mutex_);
      if (error && !error_) error_ = error;
      last = --running_ == 0;
    }
    if (last) finished_.notify_one();
  }
}

namespace {

// The island of a constraint, as Bullet's own island callback finds it.
int islandOf(const btTypedConstraint* c) {
  const int a = c->getRigidBodyA().getIslandTag();
  return a >= 0 ? a : c->getRigidBodyB().getIslandTag();
}
int islandOf(const btMultiBodyConstraint* c) {
  const int a = c->getIslandIdA();
  return a >= 0 ? a : c->getIslandIdB();
}

// The constraints of `island` in an array sorted by island: appended to `out`
// (found by bisection: every island of every step looks them up).
template <class T>
void appendIsland(T** sorted, int n, int island, btAlignedObjectArray<T*>& out) {
  T** i = std::lower_bound(sorted, sorted + n, island,
                           [](const T* c, int id) { return islandOf(c) < id; });
  for (; i != sorted + n && islandOf(*i) == island; ++i) out.push_back(*i);
}

}  // namespace

ParallelIslandSolver::ParallelIslandSolver(
    int threads, const std::function<std::unique_ptr<btMultiBodyConstraintSolver>()>& make_solver)
    : active_(threads), threads_(threads) {
  for (int i = 0; i < threads; ++i) solvers_.push_back(make_solver());
  shares_.resize(static_cast<size_t>(threads));
  load_.resize(shares_.size());
  job_ = [this](int t) {
    for (const size_t i : shares_[static_cast<size_t>(t)]) solveBatch(t, batches_[i]);
  };
}

void ParallelIslandSolver::setup(const btContactSolverInfo& info, btTypedConstraint** constraints,
                                 int num_constraints, btMultiBodyConstraint** multibody_constraints,
                                 int num_multibody_constraints, const int* multibody_islands) {
  multibody_islands_ = multibody_islands;
  info_ = &info;
  constraints_ = constraints;
  num_constraints_ = num_constraints;
  multibody_constraints_ = multibody_constraints;
  num_multibody_constraints_ = num_multibody_constraints;
  batch_count_ = 0;
  batch_open_ = false;
}

ParallelIslandSolver::Batch& ParallelIslandSolver::openBatch() {
  if (!batch_open_) {
    if (batch_count_ == batches_.size()) batches_.emplace_back();
    Batch& b = batches_[batch_count_++];
    b.bodies.resize(0);
    b.manifolds.resize(0);
    b.constraints.resize(0);
    b.multibody_constraints.resize(0);
    b.cost = 0;
    batch_open_ = true;
  }
  return batches_[batch_count_ - 1];
}

void ParallelIslandSolver::processIsland(btCollisionObject** bodies, int num_bodies,
                                         btPersistentManifold** manifolds, int num_manifolds,
                                         int island_id) {
  Batch& batch = openBatch();
  for (int i = 0; i < num_bodies; ++i) batch.bodies.push_back(bodies[i]);
  for (int i = 0; i < num_manifolds; ++i) {
    batch.manifolds.push_back(manifolds[i]);
    batch.cost += 3L * manifolds[i]->getNumContacts();  // a normal and two friction rows
  }
  const int constraints_before = batch.constraints.size(),
            multibody_before = batch.multibody_constraints.size();
  appendIsland(constraints_, num_constraints_, island_id, batch.constraints);
  if (multibody_islands_) {
    const int* end = multibody_islands_ + num_multibody_constraints_;
    for (const int* i = std::lower_bound(multibody_islands_, end, island_id);
         i != end && *i == island_id; ++i)
      batch.multibody_constraints.push_back(multibody_constraints_[i - multibody_islands_]);
  } else {
    appendIsland(multibody_constraints_, num_multibody_constraints_, island_id,
                 batch.multibody_constraints);
  }
  batch.cost += (batch.constraints.size() - constraints_before) +
                (batch.multibody_constraints.size() - multibody_before) + 1;
  // Bullet's rule (MultiBodyInplaceSolverIslandCallback::processIsland).
  if (batch.multibody_constraints.size() + batch.constraints.size() + batch.manifolds.size() >
      info_->m_minimumSolverBatchSize)
    batch_open_ = false;
}

void ParallelIslandSolver::solveBatch(int thread, Batch& batch) {
  const auto data = [](auto& a) { return a.size() ? &a[0] : nullptr; };
  if (prologue_) (*prologue_)(data(batch.bodies), batch.bodies.size(), thread);
  solvers_[static_cast<size_t>(thread)]->solveMultiBodyGroup(
      data(batch.bodies), batch.bodies.size(), data(batch.manifolds), batch.manifolds.size(),
      data(batch.constraints), batch.constraints.size(), data(batch.multibody_constraints),
      batch.multibody_constraints.size(), *info_, debug_draw_, dispatcher_);
}

void ParallelIslandSolver::solve(btIDebugDraw* debug_draw, btDispatcher* dispatcher,
                                 const Prologue* prologue) {
  debug_draw_ = debug_draw;
  dispatcher_ = dispatcher;
  prologue_ = prologue;
  // Largest batch first, each to the thread with the least work so far (the
  // arrays keep their capacity: no allocation once warmed up).
  order_.resize(batch_count_);
  std::iota(order_.begin(), order_.end(), size_t{0});
  std::sort(order_.begin(), order_.end(), [&](size_t a, size_t b) {
    return batches_[a].cost != batches_[b].cost ? batches_[a].cost > batches_[b].cost : a < b;
  });
  std::fill(load_.begin(), load_.end(), 0L);
  for (auto& share : shares_) share.clear();
  const auto active_load_end = load_.begin() + active_;
  for (const size_t i : order_) {
    const auto t =
        static_cast<size_t>(std::min_element(load_.begin(), active_load_end) - load_.begin());
    shares_[t].push_back(i);
    load_[t] += batches_[i].cost;
  }
  if (batch_count_ < 2 || active_ == 1)
    job_(0);
  else
    threads_.run(job_);
  prologue_ = nullptr;  // the caller's, for this call only
}

}  // namespace simsoccer::engine
