// Small RAII C++ types over Cyclone DDS's C API (Debian's 0.10 has no C++
// binding): entities deleted when their owner goes, typed writers and
// readers for the idlc-generated message structs, QoS presets.
#pragma once

#include <dds/dds.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace simsoccer::net {

class DdsError : public std::runtime_error {
 public:
  DdsError(const std::string& what, dds_return_t code);
};

// Throws DdsError when a DDS call returned an error code.
dds_return_t check(dds_return_t rc, const char* what);

// An owned DDS entity (participant, topic, reader, ...): deleted, with its
// children, when this goes.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t e) : e_(e) {}
  Entity(Entity&& o) noexcept : e_(o.e_) { o.e_ = 0; }
  Entity& operator=(Entity&& o) noexcept;
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  ~Entity();
  dds_entity_t get() const { return e_; }
  explicit operator bool() const { return e_ > 0; }

 private:
  dds_entity_t e_ = 0;
};

struct DomainConfig {
  uint32_t domain = 0;
  // Cyclone XML configuration (configs/dds/loopback.xml by default);
  // empty: Cyclone's own default (or $CYCLONEDDS_URI).
  std::filesystem::path config_file;
  // s: how long peers wait before they take a participant that went silent
  // (a crashed process) for gone. Cyclone renews it by announcing the
  // participant to every peer port (61 with loopback.xml) at 4/5 of it: at
  // 22 robots a 2 s lease cost 8-10 packets and about 0.25 ms of CPU per
  // control period more than 5 s (bench net); at 5 s a killed agent's robot
  // is free after about 5 s.
  double lease = 5.0;
  // The domain id the participant shows on the network (RTPS ports and
  // discovery) when it differs from `domain`, Cyclone's ExternalDomainId:
  // several domains of one process can each look like domain 0, each in its
  // own network namespace (one Booster robot per namespace).
  std::optional<uint32_t> external_domain;
  // Its range: Cyclone counts in int64 nanoseconds, and below 0.1 s every
  // participant would announce itself to every port more than ten times a second.
  static constexpr double kMinLease = 0.1, kMaxLease = 86400.0;
};

// A participant on a domain configured from an XML file.
class Participant {
 public:
  explicit Participant(const DomainConfig& config);
  dds_entity_t get() const { return participant_.get(); }
  dds_guid_t guid() const;
  // The UDP ports of this participant's domain that take datagrams from 127.0.0.0/8 only:
  // those of its receive sockets when this participant made the domain and the domain's
  // configuration chose loopback interfaces only (Cyclone binds them to every address and
  // dds.cpp filters them); empty otherwise.
  const std::vector<uint16_t>& loopbackOnlyPorts() const { return loopback_only_ports_; }
  // The topic `name` of type `desc`, created once per participant.
  dds_entity_t topic(const dds_topic_descriptor_t& desc, const std::string& name);

 private:
  Entity domain_;  // only when this participant created the domain
  std::vector<uint16_t> loopback_only_ports_;
  Entity participant_;
  std::vector<std::pair<std::string, Entity>> topics_;
};

// QoS presets.
struct QosSpec {
  bool reliable = true;
  int depth = 1;                 // KEEP_LAST depth; <= 0: KEEP_ALL
  bool transient_local = false;  // late joiners get the last samples
  std::string partition;         // empty: the default partition; readers may use wildcards
};
dds_qos_t* makeQos(const QosSpec& spec);  // caller deletes with dds_delete_qos

template <class T>
class Writer {
 public:
  Writer(Participant& p, const dds_topic_descriptor_t& desc, const std::string& topic,
         const QosSpec& qos) {
    dds_entity_t parent = p.get();
    if (!qos.partition.empty()) {
      dds_qos_t* pq = dds_create_qos();
      dds_qset_partition1(pq, qos.partition.c_str());
      publisher_ = Entity(check(dds_create_publisher(p.get(), pq, nullptr), "create publisher"));
      dds_delete_qos(pq);
      parent = publisher_.get();
    }
    dds_qos_t* q = makeQos(qos);
    const dds_entity_t w = dds_create_writer(parent, p.topic(desc, topic), q, nullptr);
    dds_delete_qos(q);
    writer_ = Entity(check(w, "create writer"));
  }
  void write(const T& sample) { check(dds_write(writer_.get(), &sample), "write"); }
  dds_entity_t get() const { return writer_.get(); }

 private:
  Entity publisher_;  // only with a partition (declared first: deleted last)
  Entity writer_;
};

template <class T>
class Reader {
 public:
  Reader(Participant& p, const dds_topic_descriptor_t& desc, const std::string& topic,
         const QosSpec& qos)
      : kept_(std::make_unique<Kept>(desc)) {
    dds_entity_t parent = p.get();
    if (!qos.partition.empty()) {
      dds_qos_t* sq = dds_create_qos();
      dds_qset_partition1(sq, qos.partition.c_str());
      subscriber_ = Entity(check(dds_create_subscriber(p.get(), sq, nullptr), "create subscriber"));
      dds_delete_qos(sq);
      parent = subscriber_.get();
    }
    dds_qos_t* q = makeQos(qos);
    const dds_entity_t r = dds_create_reader(parent, p.topic(desc, topic), q, nullptr);
    dds_delete_qos(q);
    reader_ = Entity(check(r, "create reader"));
  }
  // Takes every available sample (loaned, returned after the callback) and
  // calls f(sample, info) for the valid ones. Returns how many.
  template <class F>
  int take(F&& f) {
    constexpr int kBatch = 64;
    void* samples[kBatch];
    dds_sample_info_t infos[kBatch];
    return takeBatches(samples, infos, kBatch, /*loaned=*/true, f);
  }
  // As take, but DDS deserialises into samples this reader keeps instead of loaning its own:
  // their sequences' buffers serve the next take too, so a reader taking a sample every
  // control period allocates and frees nothing. One thread at a time (the others wait).
  template <class F>
  int takeReusing(F&& f) {
    constexpr int kBatch = Kept::kCount;
    std::lock_guard lock(kept_->mutex);
    void* samples[kBatch];
    for (int i = 0; i < kBatch; ++i) samples[i] = &kept_->samples[i];
    dds_sample_info_t infos[kBatch];
    return takeBatches(samples, infos, kBatch, /*loaned=*/false, f);
  }
  dds_entity_t get() const { return reader_.get(); }

 private:
  // Takes batch after batch into `samples` (loaned: DDS's, returned after each batch; else
  // the caller's) until fewer than a batch come, calling f for the valid ones.
  template <class F>
  int takeBatches(void** samples, dds_sample_info_t* infos, int batch, bool loaned, F& f) {
    int total = 0;
    for (;;) {
      if (loaned) samples[0] = nullptr;
      const dds_return_t n = dds_take(reader_.get(), samples, infos, batch, batch);
      if (n <= 0) break;
      for (int i = 0; i < n; ++i)
        if (infos[i].valid_data) {
          f(*static_cast<const T*>(samples[i]), infos[i]);
          ++total;
        }
      if (loaned) dds_return_loan(reader_.get(), samples, n);
      if (n < batch) break;
    }
    return total;
  }
  // The samples takeReusing fills, freed with what their sequences hold.
  struct Kept {
    explicit Kept(const dds_topic_descriptor_t& d) : desc(&d) {}
    ~Kept() {
      for (T& s : samples) dds_sample_free(&s, desc, DDS_FREE_CONTENTS);
    }
    Kept(const Kept&) = delete;
    Kept& operator=(const Kept&) = delete;
    static constexpr int kCount = 4;
    const dds_topic_descriptor_t* desc;
    std::mutex mutex;
    T samples[kCount]{};
  };
  std::unique_ptr<Kept> kept_;
  Entity subscriber_;
  Entity reader_;
};

// The participant GUID of the writer behind a sample's publication handle
// (as this reader sees it); false if the writer is no longer known.
bool publisherParticipant(dds_entity_t reader, dds_instance_handle_t publication,
                          dds_guid_t& participant);
// The same, and the writer's partition (its first; empty: the default one).
bool publisherParticipant(dds_entity_t reader, dds_instance_handle_t publication,
                          dds_guid_t& participant, std::string& partition);
// Whether a writer is still matched with (alive for) this reader.
bool publicationMatched(dds_entity_t reader, dds_instance_handle_t publication);

// The DDS partition of one robot's own topics: its SensorFrames (with its
// perception), status, team messages to it and camera images; and its agent's
// claims, commands and team messages (so that DDS Security's permissions can
// say which robots a team's agents may write for).
inline std::string robotPartitionName(int team, int player) {
  return "robot_" + std::to_string(team) + "_" + std::to_string(player);
}

// What the simulator's readers of the agents' topics subscribe to.
inline constexpr const char* kAllRobotPartitions = "robot_*";

inline bool sameGuid(const dds_guid_t& a, const dds_guid_t& b) {
  for (int i = 0; i < 16; ++i)
    if (a.v[i] != b.v[i]) return false;
  return true;
}

}  // namespace simsoccer::net
