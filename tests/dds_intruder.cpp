// simsoccer-dds-intruder: a hostile participant for the security tests, in a
// process of its own (a process holds one DDS configuration per domain).
// With the configuration it is given, it claims robot (team, player), sends
// `commands` joint commands for it (HeadYaw to 1.5 rad) whether or not it got
// it, and reports on stdout:
//   granted 0|1 matched N sent M
// (matched: the simulator's command readers its writer matched). If its own
// DDS Security refuses it the robot's topics, it prints "refused: ..." and
// exits 4.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "simsoccer/agents/agent_client.hpp"

int main(int argc, char** argv) {
  using namespace simsoccer;
  if (argc != 7) {
    std::fprintf(stderr, "usage: %s DDS_CONFIG DOMAIN TEAM PLAYER COMMANDS CLAIM_SECONDS\n",
                 argv[0]);
    return 2;
  }
  net::DomainConfig dds;
  dds.config_file = argv[1];
  dds.domain = static_cast<uint32_t>(std::atoi(argv[2]));
  const int team = std::atoi(argv[3]), player = std::atoi(argv[4]), commands = std::atoi(argv[5]);
  std::unique_ptr<agents::AgentClient> client;
  try {
    client = std::make_unique<agents::AgentClient>(dds, team, player);
  } catch (const std::exception& e) {
    std::printf("refused: %s\n", e.what());
    return 4;
  }
  const bool granted =
      client->claim(std::atof(argv[6]), agents::AgentClient::IfOwned::WaitForRelease);
  std::vector<float> position(25, 0.0f), stiffness(25, 1.0f);
  position[0] = 1.5f;  // HeadYaw
  int sent = 0;
  simsoccer_msg_SensorFrame frame{};
  uint64_t tick = 0;
  for (int i = 0; i < commands; ++i) {
    if (i % 50 == 0 && client->receive(frame, 0.001)) tick = frame.tick;
    client->send(tick + static_cast<uint64_t>(i % 3), position, stiffness);
    ++sent;
  }
  std::printf("granted %d matched %d sent %d\n", granted ? 1 : 0, client->commandReadersMatched(),
              sent);
  return 0;
}
