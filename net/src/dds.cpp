#include "simsoccer/net/dds.hpp"

#include <fstream>
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

Participant::Participant(const DomainConfig& config) {
  if (!(config.lease >= DomainConfig::kMinLease && config.lease <= DomainConfig::kMaxLease))
    throw std::invalid_argument("DDS lease must be between " +
                                engine::formatNumber(DomainConfig::kMinLease) + " and " +
                                engine::formatNumber(DomainConfig::kMaxLease) + " s, not " +
                                engine::formatNumber(config.lease));
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
      xml << (xml.tellp() > 0 ? "," : "")
          << "<CycloneDDS><Domain><Discovery><ExternalDomainId>" << *config.external_domain
          << "</ExternalDomainId></Discovery></Domain></CycloneDDS>";
    const dds_entity_t d = dds_create_domain(config.domain, xml.str().c_str());
    // A domain this process already created keeps its configuration.
    if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET) check(d, "create domain");
    if (d > 0) domain_ = Entity(d);
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
