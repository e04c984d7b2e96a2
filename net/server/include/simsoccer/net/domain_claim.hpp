#pragma once
// One simulator per DDS domain on this host.
//
// Two simulators on one domain publish the same topics for the same robots
// (team, player): an agent's frame reader keeps the latest sample of its
// robot, whoever wrote it, so the other simulator's frames push its own out
// and its game goes differently (a missed command is a changed game). Agents
// join a domain, not a simulator; so a simulator claims its domain on the
// host before it serves it: an advisory lock (flock) on
// <temp dir>/simsoccer-dds-<topics>-<domain>.lock, released by the kernel
// when the process ends however it ends (as sim::CoreClaim's CPU locks). Across machines
// (configs/dds/lan.xml) the domain is the people's to share out: nothing here sees the network.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace simsoccer::net {

// The topics a claim is for: simsoccer's own (simulator and agents), or the
// Booster SDK's (which share no topic with them, so may share a domain).
enum class DomainTopics { Simsoccer, Booster };

class DomainInUse : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class DomainClaim {
 public:
  // Claims `domain` for `topics`, or throws DomainInUse naming the domain and
  // the process that holds it.
  static DomainClaim claim(uint32_t domain, DomainTopics topics = DomainTopics::Simsoccer);
  // The first domain from `first` to `last` that nobody on this host holds
  // (DomainInUse when all are held).
  static DomainClaim firstFree(uint32_t first, uint32_t last,
                               DomainTopics topics = DomainTopics::Simsoccer);

  DomainClaim(DomainClaim&& o) noexcept;
  DomainClaim& operator=(DomainClaim&& o) noexcept;
  DomainClaim(const DomainClaim&) = delete;
  DomainClaim& operator=(const DomainClaim&) = delete;
  ~DomainClaim();

  uint32_t domain() const { return domain_; }
  // The lock file of a claim (in the temporary directory: host-wide, as the
  // domain's ports are).
  static std::filesystem::path lockFile(uint32_t domain, DomainTopics topics);

 private:
  DomainClaim(uint32_t domain, int fd) : domain_(domain), fd_(fd) {}
  uint32_t domain_ = 0;
  int fd_ = -1;
};

}  // namespace simsoccer::net
