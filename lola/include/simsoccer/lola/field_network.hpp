// The field's network for team binaries on one machine: a bridge on the
// host and one network namespace per robot binary, addressed as on an SPL
// field (10.0.TEAM.PLAYER there, PREFIX.TEAM.PLAYER here, default 10.77), so
// that each binary binds the GameController's port 3838 and its team port
// 10000 + team for itself, receives the simulator's broadcast GameController
// packets, sends its status to the simulator's 3939 and broadcasts team
// messages to its teammates, unmodified. Made with iproute2 (`ip`, Debian's
// iproute2 package); needs root (CAP_NET_ADMIN).
#pragma once

#include <string>
#include <vector>

namespace simsoccer::lola {

struct FieldNetwork {
  std::string bridge = "simsoccer0";
  std::string prefix = "10.77";  // a /16: the host is PREFIX.0.1, robots PREFIX.TEAM.PLAYER
  std::string link_prefix = "ss";  // host ends of the robots' links: ss<team>p<player>
  std::string hostAddress() const { return prefix + ".0.1"; }
  std::string broadcast() const { return prefix + ".255.255"; }
  std::string robotAddress(int team_number, int player) const;
  std::string namespaceName(int team_number, int player) const;
};

// Runs a program (no shell), returns its output; throws std::runtime_error
// with the command line and its output when it fails.
std::string runTool(const std::vector<std::string>& args);

// The bridge with the host's address, made when constructed and removed
// when destroyed (a stale one from a killed run is replaced).
class FieldBridge {
 public:
  explicit FieldBridge(const FieldNetwork& net);
  ~FieldBridge();
  FieldBridge(const FieldBridge&) = delete;
  FieldBridge& operator=(const FieldBridge&) = delete;
  const FieldNetwork& network() const { return net_; }

 private:
  FieldNetwork net_;
};

// One robot's namespace on the bridge (which must exist), with lo up, its
// address and a default route to the host; removed when destroyed.
class RobotNamespace {
 public:
  RobotNamespace(const FieldNetwork& net, int team_number, int player);
  ~RobotNamespace();
  RobotNamespace(const RobotNamespace&) = delete;
  RobotNamespace& operator=(const RobotNamespace&) = delete;
  const std::string& name() const { return name_; }
  const std::string& address() const { return address_; }

 private:
  std::string name_, address_, host_link_;
};

}  // namespace simsoccer::lola
