// DDS Security credentials for a match, made with OpenSSL: a match authority
// (one certificate authority for identities and permissions), a governance
// document, and per identity (the simulator, team_0, team_1) a certificate,
// its private key, signed permissions and a Cyclone DDS configuration that
// loads Cyclone's own security plugins (authentication, access control,
// cryptography). A team's permissions let its agents write claims, commands
// and team messages only in its robots' partitions (robot_<team>_*) and read
// only those partitions and the game state; only the simulator may publish
// frames, status and game state. docs/security.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace simsoccer::net {

struct CredentialsOptions {
  std::filesystem::path dir;           // written into (made if missing)
  std::filesystem::path network;       // a Cyclone XML (loopback.xml, lan.xml): its settings are kept
  int days = 30;                       // validity of certificates and permissions
  // Domains the governance and permissions cover (Cyclone 0.10's access
  // control refuses ids above 230 in these documents).
  uint32_t domain_min = 0, domain_max = 230;
  // Cyclone's plugin libraries (Debian: /usr/lib/<arch>/libddsc0debian); empty: the built-in default.
  std::filesystem::path plugin_dir;
};

// Team T's identity ("team_T"); the simulator's is "simulator".
inline std::string teamIdentity(int team) {
  return "team_" + std::to_string(team);
}
// The Cyclone configuration writeMatchCredentials writes for identity `id`.
inline std::filesystem::path credentialConfig(const std::filesystem::path& dir,
                                              const std::string& id) {
  return dir / (id + ".xml");
}

// The identities written, in order.
inline const std::vector<std::string>& credentialIdentities() {
  static const std::vector<std::string> ids{"simulator", teamIdentity(0), teamIdentity(1)};
  return ids;
}

// Writes ca.pem, ca_key.pem, governance.xml/.p7s and, per identity ID,
// ID.pem, ID_key.pem, ID_permissions.xml/.p7s and ID.xml (the Cyclone
// configuration to give --dds-config). Keys are written mode 0600. Throws
// std::runtime_error naming the file on failure.
void writeMatchCredentials(const CredentialsOptions& o);

// What a secure match reads from `dir`, checked before it starts (Cyclone and OpenSSL name no
// file when one is bad): ca.pem a certificate; per identity its certificate signed by ca.pem,
// its key the certificate's, its permissions and the governance S/MIME signed by ca.pem, and
// its ID.xml naming the files of this folder (not of the one it was copied from). Throws
// std::runtime_error naming the file and what is wrong.
void checkMatchCredentials(const std::filesystem::path& dir);

// Where Cyclone's security plugins were found at build time ("" if not).
std::filesystem::path defaultSecurityPluginDir();

}  // namespace simsoccer::net
