// The GameController wire format, byte by byte, and over real UDP sockets.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <thread>
#include <vector>

#include "gc_reader.hpp"
#include "simsoccer/referee/game.hpp"
#include "simsoccer/referee/gamecontroller.hpp"
#include "simsoccer/referee/gamecontroller_link.hpp"

using namespace simsoccer::referee;

namespace {

ControlData knownState() {
  ControlData d;
  d.packet_number = 42;
  d.players_per_team = 5;
  d.competition_phase = 1;
  d.competition_type = 1;  // MOST_PASSES: distinct from its neighbours
  d.game_phase = static_cast<uint8_t>(gc::GamePhase::PenaltyShoot);
  d.state = static_cast<uint8_t>(gc::State::Playing);
  d.set_play = static_cast<uint8_t>(gc::SetPlay::CornerKick);
  d.first_half = 1;
  d.kicking_team = 13;
  d.secs_remaining = 600;  // 0x0258
  d.secondary_time = -3;   // 0xfffd
  d.teams[0].team_number = 13;
  d.teams[0].field_player_colour = 0;  // blue
  d.teams[0].goalkeeper_colour = 2;
  d.teams[0].goalkeeper = 4;
  d.teams[0].score = 2;
  d.teams[0].penalty_shot = 3;
  d.teams[0].single_shots = 0x0105;
  d.teams[0].message_budget = 1200;  // 0x04b0
  d.teams[0].players[2] = {static_cast<uint8_t>(gc::Penalty::PlayerPushing), 45};
  d.teams[1].team_number = 5;
  d.teams[1].field_player_colour = 1;  // red
  d.teams[1].score = 1;
  d.teams[1].message_budget = 0x0102;
  d.teams[1].players[19] = {static_cast<uint8_t>(gc::Penalty::Substitute), 0};
  return d;
}

}  // namespace

TEST(GameControllerPacket, KnownStateAtTheReferenceOffsets) {
  const auto b = encode(knownState());
  ASSERT_EQ(b.size(), 118u);
  EXPECT_EQ(b[0], 'R');
  EXPECT_EQ(b[1], 'G');
  EXPECT_EQ(b[2], 'm');
  EXPECT_EQ(b[3], 'e');
  EXPECT_EQ(b[4], 18);     // version
  EXPECT_EQ(b[5], 42);     // packetNumber
  EXPECT_EQ(b[6], 5);      // playersPerTeam
  EXPECT_EQ(b[7], 1);      // competitionPhase
  EXPECT_EQ(b[8], 1);      // competitionType
  EXPECT_EQ(b[9], 1);      // gamePhase PENALTYSHOOT
  EXPECT_EQ(b[10], 3);     // state PLAYING
  EXPECT_EQ(b[11], 3);     // setPlay CORNER_KICK
  EXPECT_EQ(b[12], 1);     // firstHalf
  EXPECT_EQ(b[13], 13);    // kickingTeam: a team number
  EXPECT_EQ(b[14], 0x58);  // secsRemaining 600, little-endian
  EXPECT_EQ(b[15], 0x02);
  EXPECT_EQ(b[16], 0xfd);  // secondaryTime -3
  EXPECT_EQ(b[17], 0xff);
  EXPECT_EQ(b[18], 13);    // teams[0].teamNumber
  EXPECT_EQ(b[19], 0);     // fieldPlayerColour
  EXPECT_EQ(b[20], 2);     // goalkeeperColour
  EXPECT_EQ(b[21], 4);     // goalkeeper
  EXPECT_EQ(b[22], 2);     // teams[0].score (offset 22)
  EXPECT_EQ(b[23], 3);     // penaltyShot
  EXPECT_EQ(b[24], 0x05);  // singleShots
  EXPECT_EQ(b[25], 0x01);
  EXPECT_EQ(b[26], 0xb0);  // messageBudget 1200 at 26-27
  EXPECT_EQ(b[27], 0x04);
  EXPECT_EQ(b[28 + 2 * 2], 2);       // player 3 penalty PLAYER_PUSHING
  EXPECT_EQ(b[28 + 2 * 2 + 1], 45);  // secsTillUnpenalised
  EXPECT_EQ(b[68], 5);               // teams[1].teamNumber
  EXPECT_EQ(b[69], 1);               // red
  EXPECT_EQ(b[72], 1);               // teams[1].score (offset 72)
  EXPECT_EQ(b[76], 0x02);            // teams[1].messageBudget at 76-77
  EXPECT_EQ(b[77], 0x01);
  EXPECT_EQ(b[78 + 2 * 19], 14);  // player 20: SUBSTITUTE

  // All 118 bytes, written out from the reference's offset table: every
  // byte not set above must be 0 (teams[1].goalkeeper is 1 by default).
  std::array<uint8_t, 118> want{};
  const std::vector<std::pair<size_t, uint8_t>> set = {
      {0, 'R'},   {1, 'G'},   {2, 'm'},   {3, 'e'},   {4, 18},  {5, 42},  {6, 5},     {7, 1},
      {8, 1},     {9, 1},     {10, 3},    {11, 3},    {12, 1},  {13, 13}, {14, 0x58}, {15, 0x02},
      {16, 0xfd}, {17, 0xff}, {18, 13},   {19, 0},    {20, 2},  {21, 4},  {22, 2},    {23, 3},
      {24, 0x05}, {25, 0x01}, {26, 0xb0}, {27, 0x04}, {32, 2},  {33, 45}, {68, 5},    {69, 1},
      {71, 1},    {72, 1},    {76, 0x02}, {77, 0x01}, {116, 14}};
  for (const auto& [offset, value] : set) want[offset] = value;
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(b[i], want[i]) << "byte " << i;
}

TEST(GameControllerPacket, DecodeOfEncodeIsTheIdentity) {
  std::mt19937 rng(7);
  auto byte = [&](int hi) {
    return static_cast<uint8_t>(std::uniform_int_distribution<int>(0, hi)(rng));
  };
  for (int i = 0; i < 500; ++i) {
    ControlData d;
    d.true_data = rng() % 2;
    d.packet_number = byte(255);
    d.players_per_team = byte(20);
    d.competition_phase = byte(1);
    d.competition_type = byte(1);
    d.game_phase = byte(3);
    d.state = byte(5);
    d.set_play = byte(5);
    d.first_half = byte(1);
    d.kicking_team = byte(255);
    d.secs_remaining = static_cast<int16_t>(rng());
    d.secondary_time = static_cast<int16_t>(rng());
    for (TeamInfo& t : d.teams) {
      t.team_number = byte(255);
      t.field_player_colour = byte(9);
      t.goalkeeper_colour = byte(9);
      t.goalkeeper = byte(20);
      t.score = byte(255);
      t.penalty_shot = byte(255);
      t.single_shots = static_cast<uint16_t>(rng());
      t.message_budget = static_cast<uint16_t>(rng());
      for (RobotInfo& r : t.players) r = {byte(15), byte(255)};
    }
    const auto bytes = encode(d);
    ASSERT_EQ(decodeControl(bytes), d) << "state " << i;
  }
}

TEST(GameControllerPacket, CorruptedPacketsAreRejected) {
  auto b = encode(knownState());
  auto expectError = [](std::span<const uint8_t> bytes, const char* what) {
    try {
      decodeControl(bytes);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const PacketError& e) {
      EXPECT_NE(std::string(e.what()).find("control packet"), std::string::npos) << e.what();
    }
  };
  expectError(std::span<const uint8_t>(b.data(), 117), "short");
  std::vector<uint8_t> longer(b.begin(), b.end());
  longer.push_back(0);
  expectError(longer, "long");
  auto bad = b;
  bad[2] = 'x';
  expectError(bad, "header");
  bad = b;
  bad[4] = 17;
  expectError(bad, "version");
  bad = b;
  bad[10] = 9;
  expectError(bad, "state");
}

TEST(GameControllerPacket, ReturnPacketRoundTripAndGc3Checks) {
  ReturnData r;
  r.player_num = 3;
  r.team_num = 13;
  r.fallen = 0;
  r.pose = {1500.0f, -250.5f, 0.75f};
  r.ball_age = 1.25f;
  r.ball = {320.0f, -40.0f};
  const auto b = encode(r);
  ASSERT_EQ(b.size(), 32u);
  EXPECT_EQ(std::string(b.begin(), b.begin() + 4), "RGrt");
  EXPECT_EQ(b[4], 4);
  EXPECT_EQ(b[5], 3);
  EXPECT_EQ(b[6], 13);
  float x;
  std::memcpy(&x, &b[8], 4);  // little-endian float at offset 8 (x86 is little-endian)
  EXPECT_EQ(x, 1500.0f);
  EXPECT_EQ(decodeReturn(b), r);
  auto bad = b;
  bad[5] = 21;
  EXPECT_THROW(decodeReturn(bad), PacketError);  // playerNum 1..20
  bad = b;
  bad[7] = 255;
  EXPECT_THROW(decodeReturn(bad), PacketError);  // fallen 0/1 (the C++ constructor's 255)
  r.ball_age = std::nanf("");
  EXPECT_THROW(decodeReturn(encode(r)), PacketError);  // NaN
  EXPECT_THROW(decodeReturn(std::span<const uint8_t>(b.data(), 31)), PacketError);
}

TEST(GameControllerUdp, BroadcastToLoopbackIsReceivedAndDecoded) {
  UdpReceiver receiver(0, "127.0.0.1");  // an ephemeral port: tests run side by side
  UdpSender sender("127.0.0.1", receiver.port());
  ControlData d = knownState();
  for (uint8_t n = 0; n < 3; ++n) {
    d.packet_number = n;
    sender.send(encode(d));
  }
  // A malformed datagram in between: counted and dropped by a listener.
  const std::array<uint8_t, 5> junk = {'R', 'G', 'm', 'e', 18};
  sender.send(junk);
  std::array<uint8_t, 512> buf{};
  int good = 0, bad = 0;
  for (int i = 0; i < 4; ++i) {
    const size_t n = receiver.receive(buf, 1.0);
    ASSERT_GT(n, 0u);
    try {
      const ControlData got = decodeControl(std::span<const uint8_t>(buf.data(), n));
      EXPECT_EQ(got.teams[0].message_budget, 1200);
      ++good;
    } catch (const PacketError&) {
      ++bad;
    }
  }
  EXPECT_EQ(good, 3);
  EXPECT_EQ(bad, 1);
}

// The HSL GameController's packet (v19, 198 bytes), read at the official
// offsets by the tests' own reader: competitionType and `stopped` where v18
// had competitionPhase and competitionType, 4-byte RobotInfo, the HSL codes.
TEST(GameControllerPacket, HslVersion19AtTheOfficialOffsets) {
  ControlData d = knownState();
  d.competition_type = 1;  // MIDDLE
  d.stopped = 1;
  d.teams[0].players[2].warnings = 1;
  d.teams[0].players[2].cautions = 1;
  const auto bytes = encodeHsl(d, 19);
  ASSERT_EQ(bytes.size(), 198u);
  const simsoccer::test::GcPacket p = simsoccer::test::readGcPacket(bytes);
  EXPECT_EQ(p.version, 19);
  EXPECT_EQ(p.packet_number, 42);
  EXPECT_EQ(p.competition_type, 1);
  EXPECT_EQ(p.stopped, 1);
  EXPECT_EQ(p.game_phase, 1);
  EXPECT_EQ(p.state, 3);
  EXPECT_EQ(p.set_play, 6);  // CORNER_KICK in the HSL's codes (SPL: 3)
  EXPECT_EQ(p.kicking_team, 13);
  EXPECT_EQ(p.secs_remaining, 600);
  EXPECT_EQ(p.secondary_time, -3);
  EXPECT_EQ(p.teams[0].number, 13);
  EXPECT_EQ(p.teams[0].goalkeeper_colour, 2);
  EXPECT_EQ(p.teams[0].single_shots, 0x0105);
  EXPECT_EQ(p.teams[0].message_budget, 1200);
  EXPECT_EQ(p.teams[0].players[2].penalty, 9);  // PUSHING (SPL: 2)
  EXPECT_EQ(p.teams[0].players[2].secs_till_unpenalised, 45);
  EXPECT_EQ(p.teams[0].players[2].warnings, 1);
  EXPECT_EQ(p.teams[0].players[2].cautions, 1);
  EXPECT_EQ(p.teams[1].number, 5);
  EXPECT_EQ(p.teams[1].message_budget, 0x0102);
  EXPECT_EQ(p.teams[1].players[19].penalty, 11);  // SUBSTITUTE (SPL: 14)
  // Decoded back into the SPL's codes.
  const ControlData back = decodeAnyControl(bytes);
  EXPECT_EQ(back.set_play, d.set_play);
  EXPECT_EQ(back.teams[0].players[2], d.teams[0].players[2]);
  EXPECT_EQ(back.teams[1].players[19], d.teams[1].players[19]);
  EXPECT_EQ(back.stopped, 1);
  // Standby does not exist in v19: a robot sees Initial.
  d.state = static_cast<uint8_t>(gc::State::Standby);
  EXPECT_EQ(simsoccer::test::readGcPacket(encodeHsl(d, 19)).state, 0);
  // A v18 packet is still told apart.
  int version = 0;
  decodeAnyControl(encode(knownState()), &version);
  EXPECT_EQ(version, 18);
  EXPECT_THROW(decodeAnyControl(std::span<const uint8_t>(bytes.data(), 118)), PacketError);
}

// The HSL GameController's packet of RoboCup 2026 (v20, 158 bytes; its Wireshark dissector
// game_controller_msgs/dissectors/robocup_gc.lua): v19's header part, a 3-byte RobotInfo
// (penalty, secsTillUnpenalised, cautions), the penalties renumbered (Motion in Stop 3,
// Cautioned 11 new).
TEST(GameControllerPacket, HslVersion20AtTheOfficialOffsets) {
  ControlData d = knownState();
  d.competition_type = 1;  // MIDDLE
  d.stopped = 1;
  d.teams[0].players[2].cautions = 1;
  d.teams[0].players[3].penalty = static_cast<uint8_t>(gc::Penalty::LocalGameStuck);
  d.teams[0].players[4].penalty = static_cast<uint8_t>(gc::Penalty::RequestForPickup);
  d.teams[0].players[5].penalty = static_cast<uint8_t>(gc::Penalty::InactivePlayer);
  d.teams[0].players[6].penalty = static_cast<uint8_t>(gc::Penalty::LeavingTheField);
  d.teams[0].players[7].penalty = static_cast<uint8_t>(gc::Penalty::IllegalMotionInSet);
  d.teams[0].players[8].penalty = static_cast<uint8_t>(gc::Penalty::IllegalBallContact);
  d.teams[0].players[9].penalty = static_cast<uint8_t>(gc::Penalty::IllegalPosition);
  const auto bytes = encodeHsl(d);  // the current version
  ASSERT_EQ(bytes.size(), 158u);
  const simsoccer::test::GcPacket p = simsoccer::test::readGcPacket(bytes);
  EXPECT_EQ(p.version, 20);
  EXPECT_EQ(p.packet_number, 42);
  EXPECT_EQ(p.competition_type, 1);
  EXPECT_EQ(p.stopped, 1);
  EXPECT_EQ(p.game_phase, 1);
  EXPECT_EQ(p.state, 3);
  EXPECT_EQ(p.set_play, 6);  // CORNER_KICK (SPL: 3)
  EXPECT_EQ(p.kicking_team, 13);
  EXPECT_EQ(p.secs_remaining, 600);
  EXPECT_EQ(p.secondary_time, -3);
  EXPECT_EQ(p.teams[0].number, 13);
  EXPECT_EQ(p.teams[0].goalkeeper_colour, 2);
  EXPECT_EQ(p.teams[0].single_shots, 0x0105);
  EXPECT_EQ(p.teams[0].message_budget, 1200);
  const auto& players = p.teams[0].players;
  EXPECT_EQ(players[2].penalty, 10);  // PUSHING (v19: 9, SPL: 2)
  EXPECT_EQ(players[2].secs_till_unpenalised, 45);
  EXPECT_EQ(players[2].cautions, 1);
  EXPECT_EQ(players[2].warnings, -1);  // none in v20
  EXPECT_EQ(players[3].penalty, 4);    // LOCAL_GAME_STUCK (v19: 3)
  EXPECT_EQ(players[4].penalty, 6);    // PICK_UP (v19: 5)
  EXPECT_EQ(players[5].penalty, 5);    // INCAPABLE_ROBOT (v19: 4)
  EXPECT_EQ(players[6].penalty, 8);    // LEAVING_THE_FIELD (v19: 7)
  EXPECT_EQ(players[7].penalty, 2);    // MOTION_IN_SET
  EXPECT_EQ(players[8].penalty, 9);    // PLAYING_WITH_ARMS_HANDS (v19: 8)
  EXPECT_EQ(players[9].penalty, 1);    // ILLEGAL_POSITIONING
  EXPECT_EQ(p.teams[1].number, 5);
  EXPECT_EQ(p.teams[1].message_budget, 0x0102);
  EXPECT_EQ(p.teams[1].players[19].penalty, 13);  // SUBSTITUTE (v19: 11, SPL: 14)
  // Decoded back into the SPL's codes, told apart from v18 and v19 by the version byte.
  int version = 0;
  const ControlData back = decodeAnyControl(bytes, &version);
  EXPECT_EQ(version, 20);
  EXPECT_EQ(back.set_play, d.set_play);
  for (size_t i = 2; i < 10; ++i) EXPECT_EQ(back.teams[0].players[i], d.teams[0].players[i]) << i;
  EXPECT_EQ(back.teams[1].players[19], d.teams[1].players[19]);
  EXPECT_EQ(back.stopped, 1);
  // What v20 has and the SPL has not: Motion in Stop reads as motion in Set, Cautioned and
  // Sent Off as the GameController's own penalty; past Substitute is no v20 penalty.
  auto coded = bytes;
  const size_t player0 = 18 + 10;  // teams[0].players[0].penalty
  for (const auto& [code, spl] : {std::pair{3, gc::Penalty::IllegalMotionInSet},
                                  {7, gc::Penalty::IllegalBallContact},
                                  {11, gc::Penalty::Manual},
                                  {12, gc::Penalty::Manual}}) {
    coded[player0] = static_cast<uint8_t>(code);
    EXPECT_EQ(decodeAnyControl(coded).teams[0].players[0].penalty, static_cast<uint8_t>(spl))
        << code;
  }
  coded[player0] = 14;
  EXPECT_THROW(decodeAnyControl(coded), PacketError);
  // Standby does not exist in v20 either: a robot sees Initial.
  d.state = static_cast<uint8_t>(gc::State::Standby);
  EXPECT_EQ(simsoccer::test::readGcPacket(encodeHsl(d)).state, 0);
  // A v19-sized packet that says 20 is refused by its size.
  std::vector<uint8_t> wrong = encodeHsl(knownState(), 19);
  wrong[4] = 20;
  EXPECT_THROW(decodeAnyControl(wrong), PacketError);
}

// The link sends the rule book's version, with the message budget going down as the team sends
// messages in Ready, Set and Playing (those sent in Initial, Finished and the shoot-out are
// free, as GameController3 and the HSL's count them).
TEST(GameControllerUdp, TheRuleBooksVersionGoesOutWithTheBudgetLeft) {
  for (const char* book : {"spl.yaml", "hsl_small_foundation.yaml", "hsl_middle_foundation.yaml",
                           "hsl_middle_advanced.yaml"}) {
    const RuleBook rules =
        loadRuleBook(std::filesystem::path(SIMSOCCER_SOURCE_DIR) / "configs" / "rules" / book);
    const std::string name = book;
    // HSL divisions on the wire (RoboCupGameControlData.h v19, v20): SMALL 0, MIDDLE 1;
    // the Middle division plays 3 v 3 (Foundation) and 5 v 5 (Advanced).
    const int division = name.starts_with("hsl_middle") ? 1 : 0;
    if (name.starts_with("hsl_middle")) {
      EXPECT_EQ(rules.players_per_team, name.find("advanced") != std::string::npos ? 5 : 3);
    }
    Game game(rules, {TeamSetup{7, 0, 2, 1}, TeamSetup{9, 1, 3, 1}}, 0);
    UdpReceiver robot(0, "127.0.0.1");
    GameControllerLinkConfig c;
    c.address = "127.0.0.1";
    c.control_port = robot.port();
    c.return_port = 0;
    GameControllerLink link(c);
    std::array<uint8_t, 512> buf{};
    std::vector<int> budgets;
    game.setTeamMessagesSent(0, 40);  // in Initial: free
    game.ready();
    for (uint64_t sent : {40, 50, 65}) {
      game.setTeamMessagesSent(0, sent);
      link.update(game);
      game.advance(0.5);
      const size_t n = robot.receive(buf, 1.0);
      ASSERT_GT(n, 0u) << book;
      const auto p = simsoccer::test::readGcPacket(std::span<const uint8_t>(buf.data(), n));
      EXPECT_EQ(p.version, rules.gc_version) << book;
      if (rules.gc_version != 18) {
        EXPECT_EQ(p.competition_type, division) << book;
      }
      EXPECT_EQ(p.teams[0].number, 7);
      budgets.push_back(p.teams[0].message_budget);
      EXPECT_EQ(p.teams[1].message_budget, rules.message_budget);
    }
    EXPECT_EQ(budgets, (std::vector<int>{rules.message_budget, rules.message_budget - 10,
                                         rules.message_budget - 25}))
        << book;
    game.timeout(std::nullopt);  // a referee timeout: Initial
    game.setTeamMessagesSent(0, 100);
    EXPECT_EQ(game.messageBudget(0), rules.message_budget - 25) << book;
    game.setTeamMessagesSent(1, 7);
    EXPECT_EQ(game.messageBudget(1), rules.message_budget) << book;
  }
}
