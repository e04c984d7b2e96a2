#include <gtest/gtest.h>
#include <cstdio>
#include <numbers>
#include "simsoccer/world/world.hpp"
#include "test_support.hpp"
using namespace simsoccer;
TEST(Debug, Drift) {
  auto s = test::scenario(2);
  world::World w(s);
  for (int i = 0; i < 200; ++i) w.step();
  auto p0 = w.torsoPose(0); auto p1 = w.torsoPose(1);
  const auto& m = *w.robot(0).model;
  const auto& stand = m.pose("stand");
  int knee = m.body->jointIndex("LKneePitch"), rknee = m.body->jointIndex("RKneePitch");
  int hr = m.body->jointIndex("LHipRoll"), rhr = m.body->jointIndex("RHipRoll"), ar = m.body->jointIndex("LAnkleRoll"), rar = m.body->jointIndex("RAnkleRoll");
  int hy = m.body->jointIndex("HeadYaw");
  for (int i = 0; i < 6000; ++i) {
    double t = w.time(); double sn = std::sin(2*std::numbers::pi*0.5*t);
    // robot 1 sways and squats
    w.setJointTarget(1, knee, stand[knee] + 0.2*sn, 1); w.setJointTarget(1, rknee, stand[rknee] + 0.2*sn, 1);
    w.setJointTarget(1, hr, 0.1*sn, 1); w.setJointTarget(1, rhr, 0.1*sn, 1); w.setJointTarget(1, ar, -0.1*sn, 1); w.setJointTarget(1, rar, -0.1*sn, 1);
    w.setJointTarget(1, hy, 1.0*sn, 1);
    w.step();
  }
  auto q0 = w.torsoPose(0); auto q1 = w.torsoPose(1);
  std::printf("still robot drift %.5f m, yaw %.5f; moving robot drift %.5f m yaw %.5f\n", (q0.translation()-p0.translation()).head<2>().norm(), Eigen::AngleAxisd(q0.linear()*p0.linear().transpose()).angle(),
     (q1.translation()-p1.translation()).head<2>().norm(), Eigen::AngleAxisd(q1.linear()*p1.linear().transpose()).angle());
}
