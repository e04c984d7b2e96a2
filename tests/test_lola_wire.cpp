// LoLA's wire format: the 896-byte sensor map read back by a strict reader
// written for the tests (lola_reader.hpp), and the actuator stream parser
// fed whole, split, partial, mistyped and hostile maps packed with msgpack-c.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <msgpack.hpp>
#include <numeric>
#include <string>
#include <vector>

#include "lola_reader.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/lola/actuator_stream.hpp"
#include "simsoccer/lola/sensor_packet.hpp"
#include "simsoccer/match/match_session.hpp"
#include "simsoccer/world/render_scene.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

std::span<const uint8_t> bytesOf(const msgpack::sbuffer& b) {
  return {reinterpret_cast<const uint8_t*>(b.data()), b.size()};
}

void packArray(msgpack::packer<msgpack::sbuffer>& p, const std::string& key,
               const std::vector<double>& v, bool as_double = false) {
  p.pack(key);
  p.pack_array(static_cast<uint32_t>(v.size()));
  for (double x : v) as_double ? p.pack_double(x) : p.pack_float(static_cast<float>(x));
}

}  // namespace

TEST(LolaWire, SensorMapIsExactly896BytesInLolasTypesWithTheRobotsValues) {
  world::World w(test::scenario(1));
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();  // standing, feet loaded
  const world::SensorFrame& f = w.sensorFrame(0);
  lola::BatteryModel battery(0.8);
  battery.update(f, 0.012);
  const lola::RobotIdentity id = lola::defaultIdentity(12, 3);
  const lola::SensorPacket packet =
      lola::encodeSensorPacket(lola::fromFrame(f, battery.reading()), id);
  const test::LolaSensors s = test::readLolaSensors(packet);  // throws on any deviation

  EXPECT_EQ(s.robot_config[0], "SIMSOCCERT012P030000");
  EXPECT_EQ(s.robot_config[1], "6.0.0");
  EXPECT_EQ(s.robot_config[2], "P0000000000000000000");  // the simulator's head id
  for (std::size_t j = 0; j < lola::kJoints; ++j) {
    EXPECT_EQ(s["Position"][j], f.position[j]);
    EXPECT_EQ(s["Stiffness"][j], f.stiffness[j]);
    EXPECT_EQ(s.status[j], f.status[j]);
  }
  // LoLA's raw accelerometer: about -9.81 on z for an upright robot.
  EXPECT_NEAR(s["Accelerometer"][2], -9.81, 0.6);
  EXPECT_NEAR(s["Angles"][0], f.angles[0], 1e-6);
  EXPECT_NEAR(s["Angles"][1], f.angles[1], 1e-6);
  // The FSRs in kg: the feet carry the robot's weight (5.3 kg).
  const auto& fsr = s["FSR"];
  EXPECT_NEAR(std::accumulate(fsr.begin(), fsr.end(), 0.0), 5.3, 0.8);
  EXPECT_NEAR(s["Battery"][0], 0.8, 1e-3);
  EXPECT_LT(s["Battery"][2], -1.0);  // discharging: the computer and the motors
  for (float t : s["Touch"]) EXPECT_EQ(t, 0.0f);

  w.setTouch(0, world::Touch::ChestButton, true);
  w.stepControlPeriod();
  const test::LolaSensors pressed =
      test::readLolaSensors(lola::encodeSensorPacket(lola::fromFrame(w.sensorFrame(0), {}), id));
  EXPECT_EQ(pressed["Touch"][0], 1.0f);
}

TEST(LolaWire, RobotConfigStringsHaveLolasLengths) {
  lola::RobotIdentity id = lola::defaultIdentity(1, 1);
  EXPECT_NO_THROW(lola::checkIdentity(id));
  id.body_id = "TOO-SHORT";
  try {
    lola::checkIdentity(id);
    FAIL() << "a 9-character body id was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("body_id"), std::string::npos) << e.what();
  }
  id = lola::defaultIdentity(1, 1);
  id.head_version = "v6.00";
  EXPECT_THROW(lola::checkIdentity(id), std::invalid_argument);
}

TEST(LolaWire, BatteryDrainsWithTheMotorsCurrents) {
  world::SensorFrame f;
  f.current.fill(0.2f);  // 25 x 0.2 A + 1 A for the computer = 6 A
  lola::BatteryModel b(1.0);
  for (int i = 0; i < 10000; ++i) b.update(f, 0.012);  // 120 s
  EXPECT_NEAR(b.reading().current, -6.0f, 1e-4);
  EXPECT_NEAR(b.reading().charge, 1.0 - 6.0 * 120.0 / (2.9 * 3600.0), 1e-4);
}

TEST(LolaWire, ActuatorMapsParseAsAStreamWholeSplitPartialAndMistyped) {
  lola::ActuatorValues initial;
  initial.position.fill(0.1f);
  lola::ActuatorStream stream(initial);

  std::vector<double> position(25, 0.25), stiffness(25, 1.0);
  position[0] = 0.5;
  msgpack::sbuffer full;
  {
    msgpack::packer<msgpack::sbuffer> p(full);
    p.pack_map(3);
    packArray(p, "Position", position);
    packArray(p, "Stiffness", stiffness);  // 1.0 packs as the integer 1 (msgpack-c 4.1.3)
    packArray(p, "Chest", {0.0, 0.0, 1.0});
  }
  // One byte at a time: the map is complete only at its last byte.
  std::size_t maps = 0;
  for (std::size_t i = 0; i < full.size(); ++i) {
    maps += stream.feed(bytesOf(full).subspan(i, 1));
    if (i + 1 < full.size()) {
      EXPECT_EQ(maps, 0u) << "after byte " << i;
    }
  }
  EXPECT_EQ(maps, 1u);
  EXPECT_EQ(stream.values().position[0], 0.5f);
  EXPECT_EQ(stream.values().stiffness[7], 1.0f);
  EXPECT_EQ(stream.values().chest[2], 1.0f);

  // Two partial maps in one read: float64 and integers, the rest kept.
  msgpack::sbuffer two;
  {
    msgpack::packer<msgpack::sbuffer> p(two);
    p.pack_map(1);
    std::vector<double> p2(25, 0.0);
    p2[0] = -0.75;
    packArray(p, "Position", p2, true);
    p.pack_map(2);
    packArray(p, "Stiffness", std::vector<double>(25, -1.0));  // -1: limp (Bembelbots)
    p.pack("Sonar");
    p.pack_array(2);
    p.pack(false);
    p.pack(1);
  }
  EXPECT_EQ(stream.feed(bytesOf(two)), 2u);
  EXPECT_EQ(stream.values().position[0], -0.75f);
  EXPECT_EQ(stream.values().position[1], 0.0f);   // whole-number 0.0 came as an integer
  EXPECT_EQ(stream.values().stiffness[3], 0.0f);  // clamped into 0..1
  EXPECT_EQ(stream.values().chest[2], 1.0f);      // absent: kept
  EXPECT_FALSE(stream.values().sonar[0]);
  EXPECT_TRUE(stream.values().sonar[1]);

  // A known key with the wrong length or type: the map is refused whole.
  msgpack::sbuffer bad;
  {
    msgpack::packer<msgpack::sbuffer> p(bad);
    p.pack_map(2);
    packArray(p, "Chest", {1.0, 1.0, 1.0});
    packArray(p, "Position", std::vector<double>(24, 0.0));
    p.pack_map(2);
    p.pack("Fan");
    p.pack(1);
    p.pack("Chest");
    p.pack_array(3);
    p.pack(true);
    p.pack(0);
    p.pack(0);
  }
  EXPECT_EQ(stream.feed(bytesOf(bad)), 0u);
  EXPECT_EQ(stream.counts().bad_maps, 2u);
  EXPECT_EQ(stream.values().chest[0], 0.0f);
  EXPECT_EQ(stream.values().position[0], -0.75f);

  msgpack::sbuffer unknown;
  {
    msgpack::packer<msgpack::sbuffer> p(unknown);
    p.pack_map(2);
    p.pack("Fan");
    p.pack(1);
    p.pack("SimTime");
    p.pack(3.5);
  }
  EXPECT_EQ(stream.feed(bytesOf(unknown)), 1u);
  EXPECT_EQ(stream.counts().unknown_keys, 2u);
  EXPECT_EQ(stream.counts().maps, 4u);
}

TEST(LolaWire, AnUnreadableStreamEndsWithoutBufferingWhatItClaims) {
  const auto fails = [](const std::vector<uint8_t>& bytes) {
    lola::ActuatorStream s{lola::ActuatorValues{}};
    try {
      s.feed(bytes);
    } catch (const lola::StreamError& e) {
      EXPECT_LE(s.buffered(), 64u * 1024u + 4096u) << e.what();  // the limit and one read
      return true;
    }
    return false;
  };
  EXPECT_TRUE(fails({0xc1, 0x00}));                    // never used in MessagePack
  EXPECT_TRUE(fails({0x2a}));                          // an integer, not a map
  EXPECT_TRUE(fails({0xdf, 0x7f, 0xff, 0xff, 0xff}));  // map32 of 2^31 entries
  EXPECT_TRUE(fails({0x81, 0xa8, 'P', 'o', 's', 'i', 't', 'i', 'o', 'n',  //
                     0xdd, 0x00, 0x20, 0x00, 0x00}));                     // array32 of 2 million
  // A 10 MB string value: refused at its header, long before 10 MB arrive.
  const uint8_t header[] = {0x81, 0xa3, 'F', 'a', 'n', 0xdb, 0x00, 0xa0, 0x00, 0x00};
  std::vector<uint8_t> big(sizeof header + 100 * 1024, 'x');
  std::copy(std::begin(header), std::end(header), big.begin());
  EXPECT_TRUE(fails(big));
  // Nested deeper than a map of arrays.
  EXPECT_TRUE(fails({0x81, 0xa5, 'C', 'h', 'e', 's', 't', 0x91, 0x91, 0x01}));
}

// The LED colours a LoLA client set are drawn for the spectator: the chest
// and both eyes as small spheres in those colours, on the robot.
TEST(LolaWire, LedColoursAreDrawnOnTheRobot) {
  world::World w(test::scenario(2));
  std::vector<engine::DrawItem> plain, lit;
  world::buildRenderScene(w, plain);
  world::SceneColours c;
  c.leds.resize(2);
  c.leds[1] = world::SceneColours::Leds{{0.0f, 0.0f, 1.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
  world::buildRenderScene(w, lit, c);
  ASSERT_EQ(lit.size(), plain.size() + 3);
  std::vector<Eigen::Vector3f> colours;
  for (const engine::DrawItem& item : lit)
    if (item.shape == engine::Primitive::Sphere && item.colour != c.ball)
      colours.push_back(item.colour);
  ASSERT_EQ(colours.size(), 3u);
  EXPECT_EQ(colours[0], c.leds[1]->chest);
  // On robot 1: within 0.25 m of its torso (the eyes are 0.2 m above it).
  for (const engine::DrawItem& item : lit)
    if (item.shape == engine::Primitive::Sphere && item.colour != c.ball) {
      EXPECT_LT(
          (item.transform.block<3, 1>(0, 3).cast<double>() - w.torsoPose(1).translation()).norm(),
          0.25);
    }
}

// A match config names LoLA robots and, per robot, the RobotConfig strings it
// reports; a string of the wrong length is refused at load, naming the key.
TEST(LolaWire, AMatchConfigGivesEachLolaRobotItsIdentity) {
  test::TempDir dir("lola_identity");
  std::string text = test::readFile(test::sourceDir() / "configs" / "match_2v2.yaml");
  const auto absolute = [&](const std::string& rel) {
    const auto at = text.find(rel);
    ASSERT_NE(at, std::string::npos) << rel;
    text.replace(at, rel.size(), (test::sourceDir() / "configs" / rel).string());
  };
  absolute("scenarios/match_2v2.yaml");
  absolute("rules/spl.yaml");
  absolute("agents/soccer.yaml");
  const std::string good = text +
                           "lola:\n  robots: [\"2:1\"]\n  identities:\n    \"2:1\": "
                           "{body_id: P0000073A03S83I00011, head_id: P0000074A03S84F00006}\n";
  std::ofstream(dir.path() / "good.yaml") << good;
  const match::MatchConfig c = match::loadMatchConfig(dir.path() / "good.yaml");
  ASSERT_EQ(c.lola.identities.count("2:1"), 1u);
  EXPECT_EQ(c.lola.identities.at("2:1").body_id, "P0000073A03S83I00011");
  EXPECT_EQ(c.lola.identities.at("2:1").body_version, "6.0.0");
  std::ofstream(dir.path() / "bad.yaml")
      << text << "lola:\n  robots: [\"2:1\"]\n  identities:\n    \"2:1\": {body_id: SHORT}\n";
  try {
    match::loadMatchConfig(dir.path() / "bad.yaml");
    FAIL() << "a 5-character body id was accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_EQ(e.key(), "lola.identities.2:1.body_id") << e.what();
  }
}
