#include "simsoccer/lola/actuator_stream.hpp"

#include <msgpack.hpp>

#include <algorithm>
#include <cstring>
#include <string_view>

namespace simsoccer::lola {

namespace {
// The largest real map has 11 keys and arrays of 25; these limits leave room
// and bound what a hostile client can make the unpacker hold (a map header
// claiming 10 million entries is refused at its header).
constexpr std::size_t kMaxArray = 64, kMaxMap = 64, kMaxString = 64, kMaxDepth = 2;
// Bytes read per chunk handed to the unpacker.
constexpr std::size_t kChunk = 4096;
// A real actuator map is under 1 KiB. msgpack-c checks a string's limit only
// once the whole string has arrived, so an incomplete map longer than this
// ends the stream instead of being buffered.
constexpr std::size_t kMaxIncomplete = 64 * 1024;

bool toFloat(const msgpack::object& o, float& out) {
  switch (o.type) {
    case msgpack::type::POSITIVE_INTEGER: out = static_cast<float>(o.via.u64); return true;
    case msgpack::type::NEGATIVE_INTEGER: out = static_cast<float>(o.via.i64); return true;
    case msgpack::type::FLOAT32:
    case msgpack::type::FLOAT64: out = static_cast<float>(o.via.f64); return true;
    case msgpack::type::BOOLEAN: out = o.via.boolean ? 1.0f : 0.0f; return true;
    default: return false;
  }
}

template <std::size_t N>
bool readFloats(const msgpack::object& o, std::array<float, N>& out) {
  if (o.type != msgpack::type::ARRAY || o.via.array.size != N) return false;
  for (std::size_t i = 0; i < N; ++i) {
    if (o.via.array.ptr[i].type == msgpack::type::BOOLEAN) return false;
    if (!toFloat(o.via.array.ptr[i], out[i])) return false;
  }
  return true;
}

bool readBools(const msgpack::object& o, std::array<bool, 2>& out) {
  if (o.type != msgpack::type::ARRAY || o.via.array.size != 2) return false;
  for (std::size_t i = 0; i < 2; ++i) {
    float v = 0.0f;
    if (!toFloat(o.via.array.ptr[i], v)) return false;
    out[i] = v != 0.0f;
  }
  return true;
}

// Merges one map into `values` if every known key in it is well formed
// (a map is taken whole or not at all). Unknown keys are counted.
bool merge(const msgpack::object& map, ActuatorValues& values, uint64_t& unknown_keys,
           bool& joints) {
  ActuatorValues next = values;
  uint64_t unknown = 0;
  joints = false;
  for (uint32_t i = 0; i < map.via.map.size; ++i) {
    const msgpack::object& k = map.via.map.ptr[i].key;
    const msgpack::object& v = map.via.map.ptr[i].val;
    std::string_view key;
    if (k.type == msgpack::type::STR)
      key = {k.via.str.ptr, k.via.str.size};
    else if (k.type == msgpack::type::BIN)  // old-spec "raw"
      key = {k.via.bin.ptr, k.via.bin.size};
    else
      return false;
    bool ok = true;
    if (key == "Position") ok = readFloats(v, next.position), joints = true;
    else if (key == "Stiffness") ok = readFloats(v, next.stiffness), joints = true;
    else if (key == "Chest") ok = readFloats(v, next.chest), next.leds_set = true;
    else if (key == "LFoot") ok = readFloats(v, next.lfoot);
    else if (key == "RFoot") ok = readFloats(v, next.rfoot);
    else if (key == "LEye") ok = readFloats(v, next.leye), next.leds_set = true;
    else if (key == "REye") ok = readFloats(v, next.reye), next.leds_set = true;
    else if (key == "LEar") ok = readFloats(v, next.lear);
    else if (key == "REar") ok = readFloats(v, next.rear);
    else if (key == "Skull") ok = readFloats(v, next.skull);
    else if (key == "Sonar") ok = readBools(v, next.sonar);
    else ++unknown;
    if (!ok) return false;
  }
  // LoLA takes stiffness in 0..1; teams send -1 for "limp" (Bembelbots).
  // A NaN stays a NaN: the command gate refuses it.
  for (float& s : next.stiffness)
    if (!std::isnan(s)) s = std::clamp(s, 0.0f, 1.0f);
  // LEDs are only shown: a NaN or an out-of-range colour is made harmless.
  for (auto* leds : {next.chest.data(), next.lfoot.data(), next.rfoot.data()})
    for (int k = 0; k < 3; ++k) leds[k] = std::isfinite(leds[k]) ? std::clamp(leds[k], 0.0f, 1.0f) : 0.0f;
  for (auto* eye : {next.leye.data(), next.reye.data()})
    for (int k = 0; k < 24; ++k) eye[k] = std::isfinite(eye[k]) ? std::clamp(eye[k], 0.0f, 1.0f) : 0.0f;
  values = next;
  unknown_keys += unknown;
  return true;
}
}  // namespace

struct ActuatorStream::Unpacker {
  msgpack::unpacker unpacker{nullptr, nullptr, kChunk,
                             msgpack::unpack_limit(kMaxArray, kMaxMap, kMaxString, kMaxString, 0,
                                                   kMaxDepth)};
};

ActuatorStream::ActuatorStream(const ActuatorValues& initial)
    : unpacker_(std::make_unique<Unpacker>()), values_(initial) {}
ActuatorStream::~ActuatorStream() = default;
ActuatorStream::ActuatorStream(ActuatorStream&&) noexcept = default;
ActuatorStream& ActuatorStream::operator=(ActuatorStream&&) noexcept = default;

std::size_t ActuatorStream::buffered() const {
  return unpacker_->unpacker.nonparsed_size();
}

void ActuatorStream::restoreJoints(const std::array<float, kJoints>& position,
                                   const std::array<float, kJoints>& stiffness) {
  values_.position = position;
  values_.stiffness = stiffness;
}

void ActuatorStream::append(std::span<const uint8_t> bytes) {
  msgpack::unpacker& u = unpacker_->unpacker;
  u.reserve_buffer(bytes.size());
  std::memcpy(u.buffer(), bytes.data(), bytes.size());
  u.buffer_consumed(bytes.size());
  counts_.bytes += bytes.size();
  if (u.nonparsed_size() > kMaxIncomplete)
    throw StreamError("lola: more than " + std::to_string(kMaxIncomplete) +
                      " bytes of actuator maps wait (a map that long, or a flood)");
}

std::optional<bool> ActuatorStream::next() {
  msgpack::unpacker& u = unpacker_->unpacker;
  try {
    msgpack::object_handle handle;
    if (!u.next(handle)) return std::nullopt;
    const msgpack::object& o = handle.get();
    if (o.type != msgpack::type::MAP) throw StreamError("lola: an actuator message is not a map");
    bool joints = false;
    if (!merge(o, values_, counts_.unknown_keys, joints)) {
      ++counts_.bad_maps;
      return false;
    }
    ++counts_.maps;
    counts_.joint_maps += joints;
    return joints;
  } catch (const msgpack::size_overflow& e) {
    throw StreamError(std::string("lola: an actuator map is over the size limits (") + e.what() +
                      ")");
  } catch (const msgpack::unpack_error& e) {
    throw StreamError(std::string("lola: not MessagePack (") + e.what() + ")");
  }
}

std::size_t ActuatorStream::feed(std::span<const uint8_t> bytes) {
  std::size_t maps = 0;
  while (!bytes.empty()) {  // a chunk at a time: a hostile header fails before the rest is kept
    const std::size_t n = std::min(bytes.size(), kChunk);
    append(bytes.first(n));
    bytes = bytes.subspan(n);
    for (uint64_t before = counts_.maps; next(); before = counts_.maps)
      maps += counts_.maps - before;  // merged maps (not those refused whole)
  }
  return maps;
}

}  // namespace simsoccer::lola
