// The Booster SDK locomotion service's answers (the mode machine and the RPC
// conventions), without DDS.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "simsoccer/booster/loco_service.hpp"

using namespace simsoccer::booster;
using nlohmann::json;

namespace {
RpcAnswer call(LocoService& s, int api, const json& body, bool expect = true) {
  return s.handle(json{{"api_id", api}, {"expect_response", expect}}.dump(), body.dump());
}
}  // namespace

TEST(BoosterLoco, ModesAsTheSdkNamesThem) {
  LocoService s;  // a simulated robot starts standing (prepare)
  EXPECT_EQ(s.mode(), RobotMode::Prepare);
  RpcAnswer a = call(s, 2017, json::object());
  EXPECT_EQ(a.status, kStatusSuccess);
  EXPECT_EQ(json::parse(a.body).at("mode"), 1);
  EXPECT_EQ(call(s, 2000, {{"mode", 3}}).status, kStatusSuccess);
  EXPECT_EQ(s.mode(), RobotMode::Custom);
  EXPECT_EQ(json::parse(call(s, 2017, json::object()).body).at("mode"), 3);
  EXPECT_EQ(call(s, 2000, {{"mode", 0}}).status, kStatusSuccess);
  EXPECT_EQ(s.mode(), RobotMode::Damping);
  // Walking and soccer need a walk, which this robot has not: refused, the mode stays.
  for (int m : {2, 4}) {
    a = call(s, 2000, {{"mode", m}});
    EXPECT_EQ(a.status, kStatusServerRefused) << m;
    EXPECT_NE(a.body.find("has no walk"), std::string::npos) << a.body;
    EXPECT_EQ(s.mode(), RobotMode::Damping);
  }
  EXPECT_EQ(s.refused(), 2u);
  EXPECT_EQ(s.requests(), 6u);
}

TEST(BoosterLoco, HeadTurnsInPrepareMode) {
  LocoService s;
  EXPECT_EQ(call(s, 2004, {{"pitch", 0.2}, {"yaw", -0.5}}).status, kStatusSuccess);
  ASSERT_TRUE(s.headTarget());
  EXPECT_DOUBLE_EQ(s.headTarget()->pitch, 0.2);
  EXPECT_DOUBLE_EQ(s.headTarget()->yaw, -0.5);
  call(s, 2000, {{"mode", 3}});
  EXPECT_FALSE(s.headTarget());  // custom: the client commands the head itself
  EXPECT_EQ(call(s, 2004, {{"pitch", 0.2}, {"yaw", 0.1}}).status, kStatusStateTransitionFailed);
}

TEST(BoosterLoco, MotionCallsAreRefusedAndBadRequestsNamed) {
  LocoService s;
  for (int api : {2001, 2007, 2008, 2024, 2025, 2038, 2042})
    EXPECT_EQ(call(s, api, {{"vx", 0.5}}).status, kStatusServerRefused) << api;
  // Bad requests: 400, and the service goes on.
  EXPECT_EQ(s.handle("{not json", "{}").status, kStatusBadRequest);
  EXPECT_EQ(s.handle(R"({"api_id": "2000"})", "{}").status, kStatusBadRequest);
  EXPECT_EQ(s.handle(R"({"api_id": 1e300})", "{}").status, kStatusBadRequest);
  EXPECT_EQ(s.handle(R"({"api_id": 2000.5})", "{}").status, kStatusBadRequest);
  EXPECT_EQ(s.handle(R"({"api_id": 9999})", "{}").status, kStatusBadRequest);
  EXPECT_EQ(s.handle(R"({"api_id": 2014})", "{}").status, kStatusBadRequest);  // not the SDK's
  EXPECT_EQ(call(s, 2000, {{"mode", 7}}).status, kStatusBadRequest);
  EXPECT_EQ(call(s, 2000, {{"mode", "custom"}}).status, kStatusBadRequest);
  EXPECT_EQ(s.handle(R"({"api_id": 2000})", "[1, 2]").status, kStatusBadRequest);
  EXPECT_EQ(call(s, 2004, {{"pitch", 0.1}}).status, kStatusBadRequest);
  EXPECT_EQ(s.malformed(), 10u);
  EXPECT_EQ(s.mode(), RobotMode::Prepare);
  // A fire-and-forget request gets no answer but is carried out.
  const RpcAnswer quiet = call(s, 2000, {{"mode", 3}}, false);
  EXPECT_FALSE(quiet.respond);
  EXPECT_EQ(s.mode(), RobotMode::Custom);
  // GetMode may come with an empty body.
  EXPECT_EQ(s.handle(R"({"api_id": 2017, "expect_response": true})", "").status, kStatusSuccess);
  // The SDK's other calls (hands, dances, sounds, queries): 501 naming the call, not 400 (the
  // SDK's "request param invalid", which would send a team looking for its own bug).
  for (int api : {2005, 2022, 2030, 2035, 2044, 2046, 2050}) {
    const RpcAnswer a = call(s, api, json::object());
    EXPECT_EQ(a.status, kStatusServerRefused) << api;
    EXPECT_NE(a.body.find(unservedLocoApiName(api)), std::string::npos) << a.body;
  }
  EXPECT_STREQ(unservedLocoApiName(2022), "GetRobotInfo");
  EXPECT_EQ(unservedLocoApiName(2014), nullptr);
  // ResetOdometry: answered, counted for the endpoint (which moves the odometry's origin).
  EXPECT_EQ(call(s, 2031, json::object()).status, kStatusSuccess);
  EXPECT_EQ(s.odometryResets(), 1u);
  EXPECT_EQ(s.malformed(), 10u);
}

// A robot with simsoccer's walk (the K1): Walking and Soccer are served, Move sets the walk's
// velocity there and only there, the head turns, GetUp is the walk's own fall recovery.
TEST(BoosterLoco, WithAWalkMoveDrivesItInWalkingAndSoccerMode) {
  LocoService s(RobotMode::Prepare, {.walk = true});
  EXPECT_FALSE(s.walking());
  // Move and GetUp outside walking and soccer: not from this state, nothing changes.
  EXPECT_EQ(call(s, 2001, {{"vx", 0.3}, {"vy", 0.0}, {"vyaw", 0.0}}).status,
            kStatusStateTransitionFailed);
  EXPECT_EQ(call(s, 2008, json::object()).status, kStatusStateTransitionFailed);
  EXPECT_EQ(s.velocity().vx, 0.0);
  EXPECT_EQ(call(s, 2000, {{"mode", 2}}).status, kStatusSuccess);
  EXPECT_TRUE(s.walking());
  EXPECT_EQ(call(s, 2001, {{"vx", 0.3}, {"vy", -0.1}, {"vyaw", 0.5}}).status, kStatusSuccess);
  EXPECT_DOUBLE_EQ(s.velocity().vx, 0.3);
  EXPECT_DOUBLE_EQ(s.velocity().vy, -0.1);
  EXPECT_DOUBLE_EQ(s.velocity().vyaw, 0.5);
  EXPECT_EQ(call(s, 2004, {{"pitch", 0.3}, {"yaw", 0.2}}).status, kStatusSuccess);
  ASSERT_TRUE(s.headTarget());
  EXPECT_EQ(call(s, 2008, json::object()).status, kStatusSuccess);
  // Walking to soccer keeps walking at the same velocity; a bad Move changes nothing.
  EXPECT_EQ(call(s, 2000, {{"mode", 4}}).status, kStatusSuccess);
  EXPECT_DOUBLE_EQ(s.velocity().vx, 0.3);
  EXPECT_EQ(call(s, 2001, {{"vx", 0.3}, {"vy", "fast"}, {"vyaw", 0.0}}).status, kStatusBadRequest);
  EXPECT_EQ(call(s, 2001, {{"vx", 1e9}, {"vy", 0.0}, {"vyaw", 0.0}}).status, kStatusBadRequest);
  EXPECT_DOUBLE_EQ(s.velocity().vx, 0.3);
  // Without a kick approach no kicks; LieDown is not served.
  EXPECT_EQ(call(s, 2038, {{"start", true}}).status, kStatusServerRefused);
  EXPECT_EQ(call(s, 2024, json::object()).status, kStatusServerRefused);
  EXPECT_EQ(call(s, 2007, json::object()).status, kStatusServerRefused);
  // Back to prepare: standing, the velocity forgotten; walking again starts from rest.
  EXPECT_EQ(call(s, 2000, {{"mode", 1}}).status, kStatusSuccess);
  EXPECT_FALSE(s.walking());
  EXPECT_EQ(call(s, 2000, {{"mode", 2}}).status, kStatusSuccess);
  EXPECT_EQ(s.velocity().vx, 0.0);
}

// A robot with a walk and a kick approach (the K1): Shoot and VisualKick in Walking and
// Soccer with the robot on its feet; the visual kick runs until stopped, the mode left or a
// fall; malformed kicks named.
TEST(BoosterLoco, KicksInWalkingAndSoccerModeOnItsFeet) {
  LocoService s(RobotMode::Prepare, {.walk = true, .kicks = true, .vision = true});
  EXPECT_EQ(call(s, 2024, json::object()).status, kStatusStateTransitionFailed);
  EXPECT_EQ(call(s, 2038, {{"start", true}, {"version", 0}}).status, kStatusStateTransitionFailed);
  EXPECT_FALSE(s.takeShoot());
  EXPECT_FALSE(s.visualKick());
  // Stopping is always allowed.
  EXPECT_EQ(call(s, 2038, {{"start", false}, {"version", 0}}).status, kStatusSuccess);
  EXPECT_EQ(call(s, 2000, {{"mode", 4}}).status, kStatusSuccess);
  // Shoot: one kick, the walk's velocity forgotten.
  EXPECT_EQ(call(s, 2001, {{"vx", 0.3}, {"vy", 0.0}, {"vyaw", 0.0}}).status, kStatusSuccess);
  EXPECT_EQ(call(s, 2024, json::object()).status, kStatusSuccess);
  EXPECT_TRUE(s.takeShoot());
  EXPECT_FALSE(s.takeShoot());
  EXPECT_EQ(s.velocity().vx, 0.0);
  // VisualKick: the body as the SDK writes it ({"start", "version"}; version 1 is V2).
  EXPECT_EQ(call(s, 2038, {{"start", true}, {"version", 1}}).status, kStatusSuccess);
  EXPECT_TRUE(s.visualKick());
  EXPECT_EQ(s.visualKickVersion(), 1);
  EXPECT_EQ(call(s, 2024, json::object()).status, kStatusStateTransitionFailed);
  EXPECT_FALSE(s.takeShoot());
  // Down: it ends, and kicks wait until the robot is up.
  s.setDown(true);
  EXPECT_FALSE(s.visualKick());
  EXPECT_EQ(call(s, 2038, {{"start", true}, {"version", 0}}).status, kStatusStateTransitionFailed);
  EXPECT_EQ(call(s, 2024, json::object()).status, kStatusStateTransitionFailed);
  s.setDown(false);
  EXPECT_EQ(call(s, 2038, {{"start", true}}).status, kStatusSuccess);  // version: V1
  EXPECT_EQ(s.visualKickVersion(), 0);
  // Soccer to walking keeps it; prepare ends it.
  EXPECT_EQ(call(s, 2000, {{"mode", 2}}).status, kStatusSuccess);
  EXPECT_TRUE(s.visualKick());
  EXPECT_EQ(call(s, 2000, {{"mode", 1}}).status, kStatusSuccess);
  EXPECT_FALSE(s.visualKick());
  // Malformed: 400, nothing changes (the running visual kick, its version).
  call(s, 2000, {{"mode", 4}});
  EXPECT_EQ(call(s, 2038, {{"start", true}, {"version", 1}}).status, kStatusSuccess);
  const uint64_t malformed = s.malformed(), starts = s.visualKickStarts();
  for (const json& body :
       {json{{"start", "yes"}}, json{{"version", 1}}, json{{"start", true}, {"version", 2}},
        json{{"start", true}, {"version", "V2"}}}) {
    const RpcAnswer a = call(s, 2038, body);
    EXPECT_EQ(a.status, kStatusBadRequest) << body.dump();
    EXPECT_NE(a.body.find("VisualKick"), std::string::npos) << a.body;
  }
  EXPECT_EQ(s.malformed(), malformed + 4);
  EXPECT_TRUE(s.visualKick());
  EXPECT_EQ(s.visualKickVersion(), 1);
  EXPECT_EQ(s.visualKickStarts(), starts);
  // A stop and a start: a new start (the approach starts over).
  call(s, 2038, {{"start", false}});
  call(s, 2038, {{"start", true}});
  EXPECT_EQ(s.visualKickStarts(), starts + 1);
  // Without the simulation's perception the robot would see no ball: no visual kick; Shoot
  // needs none.
  LocoService blind(RobotMode::Soccer, {.walk = true, .kicks = true});
  const RpcAnswer a = call(blind, 2038, {{"start", true}, {"version", 1}});
  EXPECT_EQ(a.status, kStatusServerRefused);
  EXPECT_NE(a.body.find("perception"), std::string::npos) << a.body;
  EXPECT_EQ(call(blind, 2024, json::object()).status, kStatusSuccess);
}
