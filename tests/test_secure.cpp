// DDS Security (simsoccer credentials, docs/security.md): the simulator in
// this process with its credentials; its agent, strangers and the other team
// as processes with theirs (a process holds one DDS configuration per domain).
#include <gtest/gtest.h>
#include <openssl/pem.h>
#include <openssl/x509.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <future>
#include <string>
#include <vector>

#include "agent_process.hpp"
#include "simsoccer/net/credentials.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

// Credentials of one match authority in a folder of the test's own.
struct Credentials {
  explicit Credentials(const std::string& name) : dir(name) {
    net::CredentialsOptions o;
    o.dir = dir.path();
    o.network = test::sourceDir() / "configs" / "dds" / "loopback.xml";
    net::writeMatchCredentials(o);
  }
  std::filesystem::path operator/(const std::string& file) const { return dir / file; }
  test::TempDir dir;
};

// An intruder (tests/dds_intruder.cpp) run while the simulation steps: its report.
std::future<std::string> intrude(const std::filesystem::path& dds_config, uint32_t domain, int team,
                                 int player, int commands, double claim_seconds) {
  const std::string cmd = std::string(SIMSOCCER_INTRUDER_BIN) + " " + dds_config.string() + " " +
                          std::to_string(domain) + " " + std::to_string(team) + " " +
                          std::to_string(player) + " " + std::to_string(commands) + " " +
                          std::to_string(claim_seconds);
  return std::async(std::launch::async, [cmd] {
    int status = 0;
    return test::runCommand(cmd, status);
  });
}

bool ready(const std::future<std::string>& f) {
  return f.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

}  // namespace

TEST(Secure, CredentialsAreSignedByTheMatchAuthority) {
  const Credentials c("secure_files");
  int status = 0;
  for (const std::string id : {"simulator", "team_0", "team_1"}) {
    std::string out = test::runCommand(
        "openssl verify -CAfile " + (c / "ca.pem").string() + " " + (c / (id + ".pem")).string(),
        status);
    EXPECT_EQ(status, 0) << out;
    out = test::runCommand("openssl smime -verify -text -CAfile " + (c / "ca.pem").string() +
                               " -in " + (c / (id + "_permissions.p7s")).string(),
                           status);
    EXPECT_EQ(status, 0) << out;
    EXPECT_NE(out.find("<subject_name>CN=" + id + ",O=simsoccer</subject_name>"), std::string::npos)
        << out;
    EXPECT_EQ(std::filesystem::status(c / (id + "_key.pem")).permissions() &
                  std::filesystem::perms::others_read,
              std::filesystem::perms::none);
  }
  const std::string governance = test::readFile(c / "governance.xml");
  EXPECT_NE(governance.find("<allow_unauthenticated_participants>false<"), std::string::npos);
  EXPECT_NE(governance.find("<topic_expression>simsoccer_GameState</topic_expression>"),
            std::string::npos);
  EXPECT_NE(governance.find("SIGN_WITH_ORIGIN_AUTHENTICATION"), std::string::npos);
  const std::string team0 = test::readFile(c / "team_0_permissions.xml");
  EXPECT_NE(team0.find("<partition>robot_0_*</partition>"), std::string::npos);
  EXPECT_EQ(team0.find("robot_1_"), std::string::npos);
}

// What a secure match reads is checked before it starts, naming the bad file (Cyclone and
// OpenSSL name none): another authority's certificate, a key that is not the certificate's,
// garbage permissions, a folder copied elsewhere (its ID.xml files name the original's files).
TEST(Secure, ABadCredentialsFolderIsRefusedNamingTheFile) {
  const Credentials c("secure_check"), other("secure_check_other");
  EXPECT_NO_THROW(net::checkMatchCredentials(c.dir.path()));
  const auto refused = [&](const std::filesystem::path& dir, const std::string& said) {
    try {
      net::checkMatchCredentials(dir);
      ADD_FAILURE() << "accepted; expected: " << said;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(said), std::string::npos) << e.what();
    }
  };
  const test::TempDir copy("secure_check_copy");
  std::filesystem::copy(c.dir.path(), copy.path(), std::filesystem::copy_options::recursive);
  refused(copy.path(), "simulator.xml: names " + (c / "ca.pem").string());
  std::filesystem::copy_file(other / "team_0.pem", c / "team_0.pem",
                             std::filesystem::copy_options::overwrite_existing);
  refused(c.dir.path(), "team_0.pem: not signed by this folder's ca.pem");
  std::filesystem::copy_file(c / "team_1.pem", c / "team_0.pem",
                             std::filesystem::copy_options::overwrite_existing);
  refused(c.dir.path(), "team_0_key.pem: not the key of");
  std::filesystem::copy_file(c / "team_0.pem", c / "team_1.pem",
                             std::filesystem::copy_options::overwrite_existing);  // undo-ish
  std::ofstream(c / "governance.p7s") << "garbage\n";
  refused(c.dir.path(), "governance.p7s: not an S/MIME signed document");
}

// A certificate out of its validity (made for --days; a clock set wrong) is refused with its
// dates, though signed by the folder's own authority: `cert` is signed again by ca_key.pem with
// its validity moved by `not_before_s` and `not_after_s` from now.
namespace {
void resign(const std::filesystem::path& dir, const std::string& cert, long not_before_s,
            long not_after_s) {
  const auto read = [](const std::filesystem::path& f) {
    FILE* in = std::fopen(f.c_str(), "r");
    if (!in) throw std::runtime_error(f.string() + ": cannot be read");
    return in;
  };
  FILE* in = read(dir / cert);
  X509* c = PEM_read_X509(in, nullptr, nullptr, nullptr);
  std::fclose(in);
  in = read(dir / "ca_key.pem");
  EVP_PKEY* ca_key = PEM_read_PrivateKey(in, nullptr, nullptr, nullptr);
  std::fclose(in);
  ASSERT_TRUE(c && ca_key);
  ASSERT_TRUE(X509_gmtime_adj(X509_getm_notBefore(c), not_before_s));
  ASSERT_TRUE(X509_gmtime_adj(X509_getm_notAfter(c), not_after_s));
  ASSERT_GT(X509_sign(c, ca_key, EVP_sha256()), 0);
  FILE* out = std::fopen((dir / cert).c_str(), "w");
  ASSERT_TRUE(out);
  ASSERT_TRUE(PEM_write_X509(out, c));
  std::fclose(out);
  X509_free(c);
  EVP_PKEY_free(ca_key);
}
}  // namespace

TEST(Secure, ACertificateOutOfItsValidityIsRefusedWithItsDates) {
  const Credentials c("secure_validity");
  const auto refused = [&](const std::string& said) {
    try {
      net::checkMatchCredentials(c.dir.path());
      ADD_FAILURE() << "accepted; expected: " << said;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(said), std::string::npos) << e.what();
    }
  };
  resign(c.dir.path(), "team_1.pem", -2 * 86400, 3600);  // still valid: signed again, accepted
  EXPECT_NO_THROW(net::checkMatchCredentials(c.dir.path()));
  resign(c.dir.path(), "team_1.pem", -2 * 86400, -86400);
  refused((c / "team_1.pem").string() + ": expired on ");
  refused("simsoccer credentials DIR --days N");
  resign(c.dir.path(), "team_1.pem", 86400, 2 * 86400);
  refused((c / "team_1.pem").string() + ": not valid before ");
}

// Without this authority's credentials a participant is not even matched;
// with the other team's, its own DDS refuses it the robot's topics, and with
// the other team's identity and permissions it signed itself the simulator
// does not match it. 13,336 commands tried, none arrives; nobody claims the
// robot, also once its agent is gone.
TEST(Secure, StrangersAndTheOtherTeamNeverReachARobot) {
  const Credentials match("secure_match"), forged("secure_forged");
  const uint32_t domain = 151;
  world::World w(test::scenario(2));
  net::ServerConfig cfg;
  cfg.dds.domain = domain;
  cfg.dds.config_file = match / "simulator.xml";
  cfg.command_timeout = 0.05;
  sim::Simulation simulation(w);
  net::SimServer server(simulation, cfg);
  auto owner = std::make_unique<test::AgentProcess>(
      domain, 0, 1, std::vector<std::string>{}, std::vector<std::string>{}, match / "team_0.xml");
  ASSERT_TRUE(server.waitForOwners(1, 30.0)) << "the team's own agent did not get its robot";
  const std::filesystem::path plain = test::sourceDir() / "configs" / "dds" / "loopback.xml";
  std::vector<std::future<std::string>> strangers;
  strangers.push_back(intrude(plain, domain, 0, 1, 3334, 3.0));
  strangers.push_back(intrude(forged / "team_0.xml", domain, 0, 1, 3334, 3.0));
  strangers.push_back(intrude(forged / "simulator.xml", domain, 0, 1, 3334, 3.0));
  // Team 1's own identity with permissions it signed itself (an authority of
  // its own, granting every robot's partition): its own DDS lets it write in
  // team 0's partition; the simulator checks the permissions against the
  // match authority and does not match it.
  {
    std::string grab = test::readFile(match / "team_1_permissions.xml");
    for (size_t at = grab.find("robot_1_*"); at != std::string::npos; at = grab.find("robot_1_*"))
      grab.replace(at, 9, "robot_*");
    std::ofstream(forged / "grab.xml") << grab;
    int status = 0;
    const std::string out = test::runCommand(
        "openssl smime -sign -text -in " + (forged / "grab.xml").string() + " -out " +
            (forged / "grab.p7s").string() + " -signer " + (forged / "ca.pem").string() +
            " -inkey " + (forged / "ca_key.pem").string(),
        status);
    ASSERT_EQ(status, 0) << out;
    std::string config = test::readFile(match / "team_1.xml");
    const auto swap = [&](const std::filesystem::path& from, const std::filesystem::path& to) {
      const size_t at = config.find("file:" + from.string());
      ASSERT_NE(at, std::string::npos) << from;
      config.replace(at, 5 + from.string().size(), "file:" + to.string());
    };
    swap(match / "ca.pem</PermissionsCA>", forged / "ca.pem</PermissionsCA>");
    swap(match / "team_1_permissions.p7s", forged / "grab.p7s");
    swap(match / "governance.p7s", forged / "governance.p7s");  // the same rules, its signature
    std::ofstream(forged / "team_1_grabs.xml") << config;
  }
  strangers.push_back(intrude(forged / "team_1_grabs.xml", domain, 0, 1, 3334, 3.0));
  auto other_team = intrude(match / "team_1.xml", domain, 0, 1, 3334, 3.0);
  const auto t0 = std::chrono::steady_clock::now();
  const auto allReady = [&] {
    for (const auto& f : strangers)
      if (!ready(f)) return false;
    return ready(other_team);
  };
  while (!allReady() && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
    simulation.period();
  ASSERT_TRUE(allReady());
  for (auto& f : strangers) {
    const std::string report = f.get();
    EXPECT_NE(report.find("granted 0 matched 0 sent 3334"), std::string::npos) << report;
  }
  const std::string refused = other_team.get();
  EXPECT_NE(refused.find("refused:"), std::string::npos) << refused;
  EXPECT_EQ(server.stats(0).refused, 0u);  // nothing of theirs even arrived
  EXPECT_GT(server.stats(0).accepted, 50u);
  EXPECT_NEAR(w.jointPosition(0, 0), 0.0, 0.05);  // HeadYaw: theirs was 1.5
  // The owner goes; a stranger still cannot have the robot.
  owner.reset();
  server.releaseRobot(0);
  auto late = intrude(plain, domain, 0, 1, 10, 2.0);
  const auto t1 = std::chrono::steady_clock::now();
  while (!ready(late) && std::chrono::steady_clock::now() - t1 < std::chrono::seconds(30))
    simulation.period();
  ASSERT_TRUE(ready(late));
  const std::string report = late.get();
  EXPECT_NE(report.find("granted 0 matched 0"), std::string::npos) << report;
  EXPECT_FALSE(server.stats(0).owned);
}

// The same match over DDS Security and without it: the same game.
TEST(Secure, AMatchIsTheSameGameOverDdsSecurity) {
  const Credentials c("secure_hash");
  const test::TempDir out("secure_hash_out");
  const auto play = [&](const std::string& name, const std::string& options) {
    int status = 0;
    const std::string log = test::runCommand(
        std::string(SIMSOCCER_BIN) + " match " +
            (test::sourceDir() / "configs" / "match_2v2.yaml").string() +
            " --max-seconds 10 --no-video --quiet --out " + (out / name).string() + " " + options,
        status);
    EXPECT_EQ(status, 0) << log;
    const std::string summary = test::readFile(out / name / "summary.json");
    const size_t at = summary.find("\"final_state_hash\": \"");
    return at == std::string::npos ? std::string("none") : summary.substr(at + 21, 16);
  };
  const std::string plain = play("plain", "--domain 152");
  const std::string secure = play("secure", "--domain 153 --secure " + c.dir.path().string());
  std::printf("final state hash: plain %s, secure %s\n", plain.c_str(), secure.c_str());
  EXPECT_NE(plain, "none");
  EXPECT_EQ(plain, secure);
}
