#include "simsoccer/net/dds.hpp"

#include <linux/filter.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "simsoccer/engine/config.hpp"

namespace simsoccer::net {

DdsError::DdsError(const std::string& what, dds_return_t code)
    : std::runtime_error("DDS: " + what + " failed: " + dds_strretcode(code)) {}

dds_return_t check(dds_return_t rc, const char* what) {
  if (rc < 0) throw DdsError(what, rc);
  return rc;
}

Entity& Entity::operator=(Entity&& o) noexcept {
  if (this != &o) {
    if (e_ > 0) dds_delete(e_);
    e_ = o.e_;
    o.e_ = 0;
  }
  return *this;
}

Entity::~Entity() {
  if (e_ > 0) dds_delete(e_);
}

namespace {

// The process's IPv4 UDP sockets, by descriptor.
std::vector<int> udpSockets() {
  std::vector<int> fds;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd", ec)) {
    char* end = nullptr;
    const std::string name = entry.path().filename().string();
    const long fd = std::strtol(name.c_str(), &end, 10);
    if (*end != '\0') continue;
    int family = 0, protocol = 0;
    socklen_t n = sizeof family;
    if (getsockopt(static_cast<int>(fd), SOL_SOCKET, SO_DOMAIN, &family, &n) != 0) continue;
    n = sizeof protocol;
    if (getsockopt(static_cast<int>(fd), SOL_SOCKET, SO_PROTOCOL, &protocol, &n) != 0) continue;
    if (family == AF_INET && protocol == IPPROTO_UDP) fds.push_back(static_cast<int>(fd));
  }
  return fds;
}

bool isLoopback(in_addr a) {
  return (ntohl(a.s_addr) >> 24) == 127;
}

// Cyclone DDS 0.10 binds its receive sockets to 0.0.0.0 whatever interfaces it is configured
// for, and has no setting to change that (eclipse-cyclonedds/cyclonedds#1923): with
// configs/dds/loopback.xml, a datagram from the network to its port still reaches it. Its
// transmit sockets are bound to the interfaces it chose. So when every socket a domain made
// that is bound to an address is bound to a loopback one (the configuration chose loopback
// only), a socket filter on the others, in the kernel, drops every datagram whose IPv4 source
// is not 127.0.0.0/8 before Cyclone reads it. The ports it restricted.
std::vector<uint16_t> restrictToLoopback(const std::vector<int>& domain_sockets) {
  std::vector<int> receive;
  std::vector<uint16_t> ports;  // of the receive sockets
  bool loopback_bound = false;
  for (const int fd : domain_sockets) {
    sockaddr_in at{};
    socklen_t n = sizeof at;
    if (getsockname(fd, reinterpret_cast<sockaddr*>(&at), &n) != 0 || at.sin_family != AF_INET)
      return {};
    if (at.sin_addr.s_addr == htonl(INADDR_ANY)) {
      receive.push_back(fd);
      ports.push_back(ntohs(at.sin_port));
    } else if (isLoopback(at.sin_addr))
      loopback_bound = true;
    else
      return {};  // it sends on a network interface: it is meant to hear the network
  }
  if (!loopback_bound) return {};
  // Classic BPF: A = the IPv4 header's source address (SKF_NET_OFF: the network header,
  // whatever the socket type); accept 127/8 whole, drop the rest.
  sock_filter code[] = {
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, static_cast<uint32_t>(SKF_NET_OFF + 12)),
      BPF_STMT(BPF_ALU | BPF_AND | BPF_K, 0xff000000u),
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, 0x7f000000u, 0, 1),
      BPF_STMT(BPF_RET | BPF_K, 0xffffffffu),
      BPF_STMT(BPF_RET | BPF_K, 0),
  };
  const sock_fprog program{static_cast<unsigned short>(std::size(code)), code};
  for (const int fd : receive)
    if (setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &program, sizeof program) != 0)
      throw std::runtime_error("DDS: cannot restrict a loopback domain's socket to loopback");
  return ports;
}

// Domains are made one at a time, so the sockets that appear while one is made are its own.
std::mutex domain_creation;

}  // namespace

Participant::Participant(const DomainConfig& config) {
  if (!(config.lease >= DomainConfig::kMinLease && config.lease <= DomainConfig::kMaxLease))
    throw std::invalid_argument("DDS lease must be between " +
                                engine::formatNumber(DomainConfig::kMinLease) + " and " +
                                engine::formatNumber(DomainConfig::kMaxLease) + " s, not " +
                                engine::formatNumber(config.lease));
  // Also a participant without a configuration of its own may make its domain (Cyclone's
  // default, or $CYCLONEDDS_URI), with sockets of its own.
  const std::lock_guard lock(domain_creation);
  if (!config.config_file.empty() || config.external_domain) {
    std::stringstream xml;
    if (!config.config_file.empty()) {
      std::ifstream f(config.config_file);
      if (!f)
        throw std::runtime_error(config.config_file.string() + ": cannot read DDS configuration");
      xml << f.rdbuf();
    }
    // Cyclone reads a list of configurations, later ones adding to earlier ones.
    if (config.external_domain)
      xml << (xml.tellp() > 0 ? "," : "") << "<CycloneDDS><Domain><Discovery><ExternalDomainId>"
          << *config.external_domain << "</ExternalDomainId></Discovery></Domain></CycloneDDS>";
    const std::vector<int> before = udpSockets();
    const dds_entity_t d = dds_create_domain(config.domain, xml.str().c_str());
    // A domain this process already created keeps its configuration.
    if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET) {
      if (config.config_file.empty()) check(d, "create domain");
      // Cyclone names the configuration "CYCLONEDDS_URI+0" in what it prints.
      throw std::runtime_error(config.config_file.string() +
                               ": Cyclone DDS refused this configuration (its messages above; "
                               "\"CYCLONEDDS_URI+0\" is this file) and created no domain " +
                               std::to_string(config.domain));
    }
    if (d > 0) {
      domain_ = Entity(d);
      std::vector<int> made;
      for (const int fd : udpSockets())
        if (std::find(before.begin(), before.end(), fd) == before.end()) made.push_back(fd);
      loopback_only_ports_ = restrictToLoopback(made);
    }
  }
  dds_qos_t* q = dds_create_qos();
  dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, static_cast<dds_duration_t>(config.lease * 1e9));
  const dds_entity_t p = dds_create_participant(config.domain, q, nullptr);
  dds_delete_qos(q);
  participant_ = Entity(check(p, "create participant"));
}

dds_guid_t Participant::guid() const {
  dds_guid_t g;
  check(dds_get_guid(participant_.get(), &g), "get participant GUID");
  return g;
}

dds_entity_t Participant::topic(const dds_topic_descriptor_t& desc, const std::string& name) {
  for (const auto& [n, t] : topics_)
    if (n == name) return t.get();
  const dds_entity_t t = check(
      dds_create_topic(participant_.get(), &desc, name.c_str(), nullptr, nullptr), "create topic");
  topics_.emplace_back(name, Entity(t));
  return t;
}

dds_qos_t* makeQos(const QosSpec& spec) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, spec.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_SECS(1));
  if (spec.depth > 0)
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, spec.depth);
  else
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
  dds_qset_durability(
      q, spec.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  return q;
}

bool publisherParticipant(dds_entity_t reader, dds_instance_handle_t publication,
                          dds_guid_t& participant) {
  std::string partition;
  return publisherParticipant(reader, publication, participant, partition);
}

bool publisherParticipant(dds_entity_t reader, dds_instance_handle_t publication,
                          dds_guid_t& participant, std::string& partition) {
  dds_builtintopic_endpoint_t* ep = dds_get_matched_publication_data(reader, publication);
  if (!ep) return false;
  participant = ep->participant_key;
  partition.clear();
  uint32_t n = 0;
  char** names = nullptr;
  if (ep->qos && dds_qget_partition(ep->qos, &n, &names)) {
    if (n > 0) partition = names[0];
    for (uint32_t i = 0; i < n; ++i) dds_free(names[i]);
    dds_free(names);
  }
  dds_builtintopic_free_endpoint(ep);
  return true;
}

bool publicationMatched(dds_entity_t reader, dds_instance_handle_t publication) {
  dds_instance_handle_t handles[256];
  const dds_return_t n = dds_get_matched_publications(reader, handles, 256);
  for (dds_return_t i = 0; i < n && i < 256; ++i)
    if (handles[i] == publication) return true;
  return false;
}

}  // namespace simsoccer::net
