// simsoccer credentials: DDS Security credentials for a match (OpenSSL; net/credentials.hpp).
#include "simsoccer/net/credentials.hpp"

#include <cstdio>

#include "cli.hpp"

namespace simsoccer::apps {

namespace {
const char* kCredentialsHelp =
    "usage: simsoccer credentials DIR [--network FILE] [--days N] [--plugins DIR] [--overwrite]\n"
    "\n"
    "Makes what a secure match needs (Cyclone DDS Security: authentication, access control,\n"
    "cryptography), with OpenSSL: a match authority (ca.pem, ca_key.pem), the signed\n"
    "governance (governance.p7s: nobody without a certificate of this authority is matched;\n"
    "every message signed, team messages encrypted), and for the simulator, team_0 and\n"
    "team_1 a certificate, a private key (mode 0600), signed permissions and a Cyclone\n"
    "configuration ID.xml. A team's permissions let its agents claim, command and send team\n"
    "messages only for its own robots (partitions robot_<team>_*) and read only its robots'\n"
    "topics and the game state.\n"
    "  --network FILE  the Cyclone configuration whose network settings the ID.xml files keep\n"
    "                  (default configs/dds/loopback.xml; configs/dds/lan.xml across machines)\n"
    "  --days N        validity of the certificates and permissions (default 30)\n"
    "  --plugins DIR   where Cyclone's libdds_security_*.so are (default: found at build time)\n"
    "  --overwrite     replace the authority already in DIR (every credential it signed, handed\n"
    "                  to teams, stops working); without it such a DIR is refused\n"
    "\n"
    "Then: simsoccer match CONFIG --secure DIR, or serve --dds-config DIR/simulator.xml with\n"
    "agents started with --dds-config DIR/team_T.xml (give each team only its team_T.* files\n"
    "and ca.pem, governance.p7s). docs/security.md.\n";
}  // namespace

int credentials(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "overwrite"}, {"network", "days", "plugins"});
  if (opt.help(kCredentialsHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one output folder");
  net::CredentialsOptions o;
  o.dir = opt.positional()[0];
  o.network = findConfig(opt.get("network", ""), "configs/dds/loopback.xml");
  if (!std::filesystem::is_regular_file(o.network))
    throw UsageError("--network " + o.network.string() + ": no such file");
  o.days = opt.wholeNumber("days", 30, 1, 3650);
  o.plugin_dir = opt.get("plugins", "");
  std::error_code ec;
  if (std::filesystem::exists(o.dir / "ca.pem", ec) && !opt.flag("overwrite"))
    throw UsageError(o.dir.string() +
                     " holds a match authority (ca.pem): the credentials it signed would stop "
                     "working; give another folder, or --overwrite to replace it");
  net::writeMatchCredentials(o);
  std::printf("wrote the match authority, governance and credentials for");
  for (const auto& id : net::credentialIdentities()) std::printf(" %s", id.c_str());
  std::printf(" to %s (valid %d days; keys mode 0600)\n", o.dir.string().c_str(), o.days);
  return 0;
}

}  // namespace simsoccer::apps
