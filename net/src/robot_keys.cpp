#include "simsoccer/net/robot_keys.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

#include <cstring>
#include <stdexcept>

namespace simsoccer::net {
namespace {

std::array<uint8_t, 32> hmac(const std::array<uint8_t, 32>& key, std::string_view label,
                             const uint8_t* a, const uint8_t* b) {
  uint8_t message[64 + 32];
  size_t n = 0;
  std::memcpy(message, label.data(), label.size());
  n += label.size();
  if (a) std::memcpy(message + n, a, 16), n += 16;
  if (b) std::memcpy(message + n, b, 16), n += 16;
  std::array<uint8_t, 32> out{};
  unsigned int len = 0;
  if (!HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), message, n, out.data(), &len) ||
      len != out.size())
    throw std::runtime_error("OpenSSL HMAC-SHA256 failed");
  return out;
}

}  // namespace

MatchSecret newMatchSecret() {
  MatchSecret s{};
  if (RAND_bytes(s.data(), static_cast<int>(s.size())) != 1)
    throw std::runtime_error("OpenSSL's random generator gave no match secret");
  return s;
}

RobotKey robotKey(const MatchSecret& secret, int team, int player) {
  const std::string label = "simsoccer robot " + std::to_string(team) + " " + std::to_string(player);
  return hmac(secret, label, nullptr, nullptr);
}

Proof claimProof(const RobotKey& key, const dds_guid_t& claimant) {
  return hmac(key, "claim", claimant.v, nullptr);
}

Proof simulatorProof(const RobotKey& key, const dds_guid_t& simulator, const dds_guid_t& owner) {
  return hmac(key, "simulator", simulator.v, owner.v);
}

bool sameProof(const Proof& expected, const uint8_t* received) {
  return CRYPTO_memcmp(expected.data(), received, expected.size()) == 0;
}

std::string toHex(const RobotKey& key) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string s;
  for (uint8_t b : key) {
    s += kDigits[b >> 4];
    s += kDigits[b & 15];
  }
  return s;
}

std::optional<RobotKey> keyFromHex(std::string_view hex, std::string* why) {
  if (hex.size() != 64) {
    if (why) *why = "a robot key is 64 hex digits, not " + std::to_string(hex.size()) + " characters";
    return std::nullopt;
  }
  RobotKey key{};
  for (size_t i = 0; i < 64; ++i) {
    const char c = hex[i];
    const int v = c >= '0' && c <= '9'   ? c - '0'
                  : c >= 'a' && c <= 'f' ? c - 'a' + 10
                  : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                         : -1;
    if (v < 0) {
      if (why) *why = "a robot key is 64 hex digits; character " + std::to_string(i + 1) + " is not one";
      return std::nullopt;
    }
    key[i / 2] = static_cast<uint8_t>(key[i / 2] << 4 | v);
  }
  return key;
}

}  // namespace simsoccer::net
