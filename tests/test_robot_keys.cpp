// Robot keys (net/robot_keys.hpp): HMAC-SHA256 through OpenSSL, checked
// against values computed independently (Python's hmac module).
#include <gtest/gtest.h>

#include <string>

#include "simsoccer/net/robot_keys.hpp"

using namespace simsoccer;

namespace {
net::MatchSecret countingSecret() {
  net::MatchSecret s{};
  for (size_t i = 0; i < s.size(); ++i) s[i] = static_cast<uint8_t>(i);
  return s;
}
dds_guid_t countingGuid(uint8_t from) {
  dds_guid_t g{};
  for (uint8_t i = 0; i < 16; ++i) g.v[i] = static_cast<uint8_t>(from + i);
  return g;
}
}  // namespace

TEST(RobotKeys, KeysAndProofsAreTheirHmacs) {
  const net::RobotKey key = net::robotKey(countingSecret(), 0, 1);
  // hmac.new(bytes(range(32)), b"simsoccer robot 0 1", sha256)
  EXPECT_EQ(net::toHex(key), "e7b2490fabfc93e1728a84d386f675ccb47eb5106cc171cecfd1637a67001c6e");
  // hmac.new(key, b"claim" + bytes(range(100, 116)), sha256)
  const net::Proof claim = net::claimProof(key, countingGuid(100));
  EXPECT_EQ(net::toHex(claim), "3449e9de4c80caae077a51c606991eb3977af29921c4d48117bf11840b4adccc");
  EXPECT_TRUE(net::sameProof(claim, claim.data()));
  // Another robot, another claimant, another role: other values.
  EXPECT_NE(net::robotKey(countingSecret(), 1, 1), key);
  EXPECT_NE(net::robotKey(countingSecret(), 0, 2), key);
  const net::Proof other = net::claimProof(key, countingGuid(101));
  EXPECT_FALSE(net::sameProof(claim, other.data()));
  EXPECT_FALSE(
      net::sameProof(claim, net::simulatorProof(key, countingGuid(100), countingGuid(100)).data()));
  // Fresh secrets differ.
  EXPECT_NE(net::newMatchSecret(), net::newMatchSecret());
}

TEST(RobotKeys, HexKeysAreReadBackOrRefusedWithTheReason) {
  const net::RobotKey key = net::robotKey(countingSecret(), 1, 3);
  EXPECT_EQ(net::keyFromHex(net::toHex(key)), key);
  std::string upper = net::toHex(key);
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(net::keyFromHex(upper), key);
  std::string why;
  EXPECT_FALSE(net::keyFromHex("abc", &why));
  EXPECT_NE(why.find("64 hex digits, not 3"), std::string::npos) << why;
  std::string bad = net::toHex(key);
  bad[10] = 'g';
  EXPECT_FALSE(net::keyFromHex(bad, &why));
  EXPECT_NE(why.find("character 11"), std::string::npos) << why;
}
