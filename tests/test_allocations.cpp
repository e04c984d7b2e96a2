// The sensor work in the simulation step allocates no heap memory once
// warmed up: counted with a replaced global operator new (this test binary
// only).
#include <LinearMath/btAlignedAllocator.h>
#include <LinearMath/btAlignedObjectArray.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "simsoccer/world/world.hpp"
#include "test_support.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

// Bullet allocates through btAlignedAlloc: count those too.
void* countingBulletAlloc(size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  return std::malloc(size);
}
void countingBulletFree(void* p) {
  std::free(p);
}

// The replacements below pair malloc with free; GCC cannot see that the free in the
// replaced operator delete frees what the replaced operator new malloc'ed, and warns.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void* operator new(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

using namespace simsoccer;

TEST(Allocations, SensorFramesAllocateNothingAfterWarmUp) {
  btAlignedAllocSetCustom(countingBulletAlloc, countingBulletFree);
  // Sensors off in the World so that only the physics runs in step(); the
  // sensor system's own per-step and per-period work is driven here.
  world::Scenario s = test::scenario(10);
  s.sensors.enabled = false;
  world::World w(s);
  auto& sensors = w.sensors();
  std::vector<engine::LinkContact> contacts;
  auto period = [&](uint64_t tick) {
    for (int i = 0; i < w.stepsPerControlPeriod(); ++i) {
      w.step();
      g_counting = true;
      w.physics().linkContacts(contacts);  // what World::step shares with the sensors
      sensors.afterStep(w.physics(), contacts);
      g_counting = false;
    }
    g_counting = true;
    sensors.finishPeriod(w.physics(), tick, w.time());  // includes a sonar update every 6th
    g_counting = false;
  };
  // The counter works: a vector that grows is seen.
  g_counting = true;
  std::vector<double> grows(1000);
  g_counting = false;
  EXPECT_GT(g_allocations.load(), 0);
  g_allocations = 0;
  g_counting = true;
  btAlignedObjectArray<double> bullet_grows;
  bullet_grows.resize(1000);
  g_counting = false;
  EXPECT_GT(g_allocations.load(), 0);
  uint64_t tick = 0;
  for (int i = 0; i < 30; ++i) period(++tick);  // warm-up: buffers reach their size
  g_allocations = 0;
  for (int i = 0; i < 120; ++i) period(++tick);  // 1.2 s, 20 sonar updates
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_GT(w.sensorFrame(0).foot_weight[0], 10.0f);  // the frames were really produced
  btAlignedAllocSetCustom(nullptr, nullptr);
}
