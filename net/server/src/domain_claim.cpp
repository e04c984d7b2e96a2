#include "simsoccer/net/domain_claim.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <utility>

namespace simsoccer::net {
namespace {

const char* topicsName(DomainTopics t) {
  return t == DomainTopics::Booster ? "booster" : "simsoccer";
}

std::string domainName(uint32_t domain, DomainTopics t) {
  return std::string(t == DomainTopics::Booster ? "the Booster SDK's" : "simsoccer's") +
         " DDS domain " + std::to_string(domain);
}

// This process, for the one who finds the domain held: pid and command line.
std::string selfDescription() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string cmd((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (char& c : cmd)
    if (c == '\0') c = ' ';
  while (!cmd.empty() && cmd.back() == ' ') cmd.pop_back();
  return "pid " + std::to_string(::getpid()) + (cmd.empty() ? "" : " (" + cmd + ")");
}

// An open lock file, locked (fd >= 0), or held by another process (fd < 0,
// `holder` says by whom when it could be read).
struct Attempt {
  int fd = -1;
  std::string holder;
};

Attempt tryClaim(uint32_t domain, DomainTopics topics) {
  const std::filesystem::path file = DomainClaim::lockFile(domain, topics);
  // Read-only is enough to lock: another user's file, readable, still serves.
  bool writable = true;
  int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (fd < 0) {
    writable = false;
    fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  }
  if (fd < 0)
    throw std::runtime_error(file.string() + ": cannot open the lock file of " +
                             domainName(domain, topics));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    std::ifstream in(file);
    std::string holder;
    std::getline(in, holder);
    return {-1, holder};
  }
  if (writable) {
    const std::string me = selfDescription() + "\n";
    if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, me.data(), me.size(), 0) < 0) {
      // Who holds it is a courtesy to the next one; the lock is what counts.
    }
  }
  return {fd, {}};
}

}  // namespace

std::filesystem::path DomainClaim::lockFile(uint32_t domain, DomainTopics topics) {
  std::error_code ec;
  std::filesystem::path tmp = std::filesystem::temp_directory_path(ec);
  if (ec) tmp = "/tmp";
  return tmp / ("simsoccer-dds-" + std::string(topicsName(topics)) + "-" + std::to_string(domain) +
                ".lock");
}

DomainClaim DomainClaim::claim(uint32_t domain, DomainTopics topics) {
  Attempt a = tryClaim(domain, topics);
  if (a.fd < 0)
    throw DomainInUse(domainName(domain, topics) + " is in use on this host" +
                      (a.holder.empty() ? "" : " by " + a.holder) +
                      ": two simulators on one domain mix their robots' frames; give this one "
                      "another --domain");
  return DomainClaim(domain, a.fd);
}

DomainClaim DomainClaim::firstFree(uint32_t first, uint32_t last, DomainTopics topics) {
  for (uint32_t d = first; d <= last; ++d) {
    Attempt a = tryClaim(d, topics);
    if (a.fd >= 0) return DomainClaim(d, a.fd);
  }
  throw DomainInUse("every one of " + domainName(first, topics) + " to " + std::to_string(last) +
                    " is in use on this host");
}

DomainClaim::DomainClaim(DomainClaim&& o) noexcept
    : domain_(o.domain_), fd_(std::exchange(o.fd_, -1)) {}

DomainClaim& DomainClaim::operator=(DomainClaim&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    domain_ = o.domain_;
    fd_ = std::exchange(o.fd_, -1);
  }
  return *this;
}

DomainClaim::~DomainClaim() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

}  // namespace simsoccer::net
