// A simsoccer-agent process for the tests that start agents themselves.
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "test_support.hpp"

extern char** environ;

namespace simsoccer::test {

// A simsoccer-agent process, killed (SIGKILL) when this goes.
class AgentProcess : public ChildProcess {
 public:
  // `environment`: NAME=VALUE entries added to this process's environment.
  // `dds_config`: its Cyclone configuration (empty: configs/dds/loopback.xml).
  AgentProcess(uint32_t domain, int team, int player, std::vector<std::string> extra = {},
               std::vector<std::string> environment = {},
               const std::filesystem::path& dds_config = {})
      : ChildProcess(arguments(domain, team, player, std::move(extra), dds_config),
                     std::move(environment)) {}

 private:
  static std::vector<std::string> arguments(uint32_t domain, int team, int player,
                                            std::vector<std::string> extra,
                                            const std::filesystem::path& dds_config) {
    std::vector<std::string> args = {
        SIMSOCCER_AGENT_BIN,    "--team",         std::to_string(team), "--player",
        std::to_string(player), "--domain",       std::to_string(domain), "--dds-config",
        (dds_config.empty() ? sourceDir() / "configs/dds/loopback.xml" : dds_config).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
};

}  // namespace simsoccer::test
