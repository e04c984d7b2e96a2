#include "simsoccer/net/credentials.hpp"

#include <fcntl.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <ctime>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace simsoccer::net {
namespace {

template <class T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const { Free(p); }
};
using Key = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Deleter<X509, X509_free>>;
using Bio = std::unique_ptr<BIO, Deleter<BIO, BIO_free_all>>;
using Pkcs7 = std::unique_ptr<PKCS7, Deleter<PKCS7, PKCS7_free>>;
using Extension = std::unique_ptr<X509_EXTENSION, Deleter<X509_EXTENSION, X509_EXTENSION_free>>;

[[noreturn]] void fail(const std::string& what) {
  char buf[256] = "";
  ERR_error_string_n(ERR_get_error(), buf, sizeof buf);
  throw std::runtime_error(what + " (OpenSSL: " + buf + ")");
}

Key newKey() {
  Key k(EVP_EC_gen("P-256"));
  if (!k) fail("cannot make an EC P-256 key");
  return k;
}

void addExtension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  const Extension ext(X509V3_EXT_conf_nid(nullptr, &ctx, nid, value));
  if (!ext || !X509_add_ext(cert, ext.get(), -1))
    fail(std::string("cannot add the extension ") + value);
}

// A certificate for `key` named O=simsoccer, CN=`cn`, signed by the issuer
// (itself when issuer is null: the authority).
Cert newCert(EVP_PKEY* key, const std::string& cn, X509* issuer, EVP_PKEY* issuer_key, int days) {
  Cert c(X509_new());
  if (!c) fail("cannot make a certificate");
  X509_set_version(c.get(), 2);
  uint64_t serial = 0;
  X509_NAME* name = X509_get_subject_name(c.get());
  if (RAND_bytes(reinterpret_cast<unsigned char*>(&serial), sizeof serial) != 1 ||
      !ASN1_INTEGER_set_uint64(X509_get_serialNumber(c.get()), serial >> 1) ||
      !X509_gmtime_adj(X509_getm_notBefore(c.get()), -3600) ||  // clocks of other machines
      !X509_gmtime_adj(X509_getm_notAfter(c.get()), static_cast<long>(days) * 86400) ||
      !X509_set_pubkey(c.get(), key) ||
      !X509_NAME_add_entry_by_txt(name, "O", MBSTRING_ASC,
                                  reinterpret_cast<const unsigned char*>("simsoccer"), -1, -1, 0) ||
      !X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_ASC,
                                  reinterpret_cast<const unsigned char*>(cn.c_str()), -1, -1, 0) ||
      !X509_set_issuer_name(c.get(), issuer ? X509_get_subject_name(issuer) : name))
    fail("cannot fill in the certificate of " + cn);
  X509* signer = issuer ? issuer : c.get();
  if (issuer) {
    addExtension(c.get(), signer, NID_basic_constraints, "critical,CA:FALSE");
    addExtension(c.get(), signer, NID_key_usage, "critical,digitalSignature,keyAgreement");
  } else {
    addExtension(c.get(), signer, NID_basic_constraints, "critical,CA:TRUE");
    addExtension(c.get(), signer, NID_key_usage, "critical,keyCertSign,cRLSign,digitalSignature");
  }
  addExtension(c.get(), signer, NID_subject_key_identifier, "hash");
  if (!X509_sign(c.get(), issuer ? issuer_key : key, EVP_sha256())) fail("cannot sign " + cn);
  return c;
}

// A new file (a key: mode 0600 from its creation, never through a link).
Bio openFile(const std::filesystem::path& file, bool secret) {
  std::filesystem::remove(file);  // a left-over file keeps its mode; a new one gets ours
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                        secret ? 0600 : 0644);
  if (fd < 0) throw std::runtime_error(file.string() + ": cannot create");
  Bio b(BIO_new_fd(fd, BIO_CLOSE));
  if (!b) {
    ::close(fd);
    fail(file.string() + ": cannot write");
  }
  return b;
}

void finish(BIO* b, const std::filesystem::path& file) {
  if (BIO_flush(b) != 1) fail(file.string() + ": cannot write (disk full?)");
}

void writeCert(const std::filesystem::path& file, X509* c) {
  Bio b = openFile(file, false);
  if (!PEM_write_bio_X509(b.get(), c)) fail(file.string() + ": cannot write the certificate");
  finish(b.get(), file);
}

void writeKey(const std::filesystem::path& file, EVP_PKEY* k) {
  Bio b = openFile(file, true);
  if (!PEM_write_bio_PrivateKey(b.get(), k, nullptr, nullptr, 0, nullptr, nullptr))
    fail(file.string() + ": cannot write the key");
  finish(b.get(), file);
}

void writeText(const std::filesystem::path& file, const std::string& text) {
  Bio b = openFile(file, false);
  if (BIO_write(b.get(), text.data(), static_cast<int>(text.size())) != static_cast<int>(text.size()))
    fail(file.string() + ": cannot write");
  finish(b.get(), file);
}

// `xml` as S/MIME signed by the authority (what `openssl smime -sign -text`
// writes, and what Cyclone's access control plugin verifies).
void writeSigned(const std::filesystem::path& file, const std::string& xml, X509* ca,
                 EVP_PKEY* ca_key) {
  const int flags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM;
  Bio in(BIO_new_mem_buf(xml.data(), static_cast<int>(xml.size())));
  Pkcs7 p7(PKCS7_sign(ca, ca_key, nullptr, in.get(), flags));
  if (!p7) fail(file.string() + ": cannot sign");
  Bio out = openFile(file, false);
  if (!SMIME_write_PKCS7(out.get(), p7.get(), in.get(), flags))
    fail(file.string() + ": cannot write the signed document");
  finish(out.get(), file);
}

std::string isoTime(std::time_t t) {
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", std::gmtime(&t));
  return buf;
}

std::string domains(const CredentialsOptions& o) {
  return "<domains><id_range><min>" + std::to_string(o.domain_min) + "</min><max>" +
         std::to_string(o.domain_max) + "</max></id_range></domains>";
}

std::string topicList(const std::vector<std::string>& topics) {
  std::string s = "<topics>";
  for (const auto& t : topics) s += "<topic>" + t + "</topic>";
  return s + "</topics>";
}

// Every sample's metadata is signed with its writer's key (a participant
// without that key cannot inject one); the game state and clock, which both
// teams read (and so both hold the writer's key), also with a code per
// receiver that only the writer can make (origin authentication); team
// messages are encrypted (a team's plans are its own); no unauthenticated
// participant is matched at all.
std::string governance(const CredentialsOptions& o) {
  const auto rule = [](const std::string& topics, const char* data,
                       const char* metadata = "SIGN") {
    return std::string("      <topic_rule>\n        <topic_expression>") + topics +
           "</topic_expression>\n"
           "        <enable_discovery_protection>false</enable_discovery_protection>\n"
           "        <enable_liveliness_protection>false</enable_liveliness_protection>\n"
           "        <enable_read_access_control>true</enable_read_access_control>\n"
           "        <enable_write_access_control>true</enable_write_access_control>\n"
           "        <metadata_protection_kind>" +
           metadata + "</metadata_protection_kind>\n        <data_protection_kind>" + data +
           "</data_protection_kind>\n      </topic_rule>\n";
  };
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
         "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/"
         "omg_shared_ca_governance.xsd\">\n"
         "  <domain_access_rules>\n    <domain_rule>\n      " +
         domains(o) +
         "\n      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
         "      <enable_join_access_control>true</enable_join_access_control>\n"
         "      <discovery_protection_kind>NONE</discovery_protection_kind>\n"
         "      <liveliness_protection_kind>NONE</liveliness_protection_kind>\n"
         "      <rtps_protection_kind>NONE</rtps_protection_kind>\n"
         "      <topic_access_rules>\n" +
         rule("simsoccer_TeamMessage*", "ENCRYPT") +
         rule("simsoccer_GameState", "NONE", "SIGN_WITH_ORIGIN_AUTHENTICATION") +
         rule("simsoccer_SimClock", "NONE", "SIGN_WITH_ORIGIN_AUTHENTICATION") + rule("*", "NONE") +
         "      </topic_access_rules>\n    </domain_rule>\n  </domain_access_rules>\n</dds>\n";
}

std::string permissions(const CredentialsOptions& o, const std::string& id) {
  const std::time_t now = std::time(nullptr);
  std::string rules;
  if (id == "simulator") {
    // Everything, in every partition and in the default one (no partitions element).
    rules = "<publish>" + topicList({"*"}) + "<partitions><partition>*</partition></partitions></publish>"
            "<publish>" + topicList({"*"}) + "</publish>"
            "<subscribe>" + topicList({"*"}) + "<partitions><partition>*</partition></partitions></subscribe>"
            "<subscribe>" + topicList({"*"}) + "</subscribe>";
  } else {
    const std::string team = id.substr(id.find('_') + 1);
    const std::string robots = "<partitions><partition>robot_" + team + "_*</partition></partitions>";
    rules = "<publish>" +
            topicList({"simsoccer_JoinRequest", "simsoccer_JointCommand", "simsoccer_TeamMessageSend"}) +
            robots + "</publish><subscribe>" +
            topicList({"simsoccer_SensorFrame", "simsoccer_RobotStatus", "simsoccer_CameraImage",
                       "simsoccer_TeamMessageDeliver"}) +
            robots + "</subscribe><subscribe>" +
            topicList({"simsoccer_GameState", "simsoccer_SimClock"}) + "</subscribe>";
  }
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
         "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/"
         "omg_shared_ca_permissions.xsd\">\n  <permissions>\n    <grant name=\"" +
         id + "\">\n      <subject_name>CN=" + id + ",O=simsoccer</subject_name>\n" +
         "      <validity><not_before>" + isoTime(now - 3600) + "</not_before><not_after>" +
         isoTime(now + static_cast<std::time_t>(o.days) * 86400) + "</not_after></validity>\n" +
         "      <allow_rule>" + domains(o) + rules + "</allow_rule>\n" +
         "      <default>DENY</default>\n    </grant>\n  </permissions>\n</dds>\n";
}

// The network configuration with a <Security> section for identity `id`.
// The network configuration whose settings every ID.xml keeps, read and checked once, before
// anything is written.
std::string networkConfig(const CredentialsOptions& o) {
  std::ifstream f(o.network);
  std::stringstream ss;
  ss << f.rdbuf();
  if (!f || ss.str().rfind("</Domain>") == std::string::npos)
    throw std::runtime_error(o.network.string() + ": not a Cyclone DDS configuration with a <Domain>");
  return ss.str();
}

std::string cycloneConfig(std::string xml, const std::filesystem::path& dir, const std::string& id,
                          const std::filesystem::path& plugins) {
  const size_t end = xml.rfind("</Domain>");
  const auto file = [&](const std::string& name) { return "file:" + (dir / name).string(); };
  const auto library = [&](const char* name, const char* init, const char* fini) {
    return std::string("<Library path=\"") + (plugins / name).string() + "\" initFunction=\"" + init +
           "\" finalizeFunction=\"" + fini + "\"/>";
  };
  const std::string security =
      "    <!-- DDS Security for " + id + " (simsoccer credentials) -->\n    <Security>\n"
      "      <Authentication>" +
      library("libdds_security_auth.so", "init_authentication", "finalize_authentication") +
      "\n        <IdentityCA>" + file("ca.pem") + "</IdentityCA>\n        <IdentityCertificate>" +
      file(id + ".pem") + "</IdentityCertificate>\n        <PrivateKey>" + file(id + "_key.pem") +
      "</PrivateKey>\n      </Authentication>\n      <AccessControl>" +
      library("libdds_security_ac.so", "init_access_control", "finalize_access_control") +
      "\n        <PermissionsCA>" + file("ca.pem") + "</PermissionsCA>\n        <Governance>" +
      file("governance.p7s") + "</Governance>\n        <Permissions>" +
      file(id + "_permissions.p7s") + "</Permissions>\n      </AccessControl>\n      <Cryptographic>" +
      library("libdds_security_crypto.so", "init_crypto", "finalize_crypto") +
      "</Cryptographic>\n    </Security>\n  ";
  xml.insert(end, security);
  return xml;
}

}  // namespace

std::filesystem::path defaultSecurityPluginDir() {
  return SIMSOCCER_DDS_SECURITY_DIR;
}

void writeMatchCredentials(const CredentialsOptions& o) {
  const std::filesystem::path plugins = o.plugin_dir.empty() ? defaultSecurityPluginDir() : o.plugin_dir;
  if (plugins.empty() || !std::filesystem::exists(plugins / "libdds_security_auth.so"))
    throw std::runtime_error("Cyclone DDS's security plugins are not in '" + plugins.string() +
                             "' (Debian's libddsc0debian package has them)");
  if (o.days < 1) throw std::runtime_error("credentials must be valid for at least one day");
  const std::string network = networkConfig(o);
  std::error_code made;
  std::filesystem::create_directories(o.dir, made);
  if (made)
    throw std::runtime_error(o.dir.string() + ": cannot make the credentials folder (" +
                             made.message() + ")");
  const std::filesystem::path dir = std::filesystem::absolute(o.dir);
  Key ca_key = newKey();
  Cert ca = newCert(ca_key.get(), "simsoccer match authority", nullptr, nullptr, o.days);
  writeCert(dir / "ca.pem", ca.get());
  writeKey(dir / "ca_key.pem", ca_key.get());
  const std::string gov = governance(o);
  writeText(dir / "governance.xml", gov);
  writeSigned(dir / "governance.p7s", gov, ca.get(), ca_key.get());
  for (const std::string& id : credentialIdentities()) {
    Key key = newKey();
    Cert cert = newCert(key.get(), id, ca.get(), ca_key.get(), o.days);
    writeCert(dir / (id + ".pem"), cert.get());
    writeKey(dir / (id + "_key.pem"), key.get());
    const std::string perm = permissions(o, id);
    writeText(dir / (id + "_permissions.xml"), perm);
    writeSigned(dir / (id + "_permissions.p7s"), perm, ca.get(), ca_key.get());
    writeText(credentialConfig(dir, id), cycloneConfig(network, dir, id, plugins));
  }
}

namespace {

Bio readFile(const std::filesystem::path& file) {
  Bio b(BIO_new_file(file.c_str(), "r"));
  if (!b) throw std::runtime_error(file.string() + ": cannot be read");
  return b;
}

Cert readCert(const std::filesystem::path& file) {
  Cert c(PEM_read_bio_X509(readFile(file).get(), nullptr, nullptr, nullptr));
  if (!c) fail(file.string() + ": not a PEM certificate");
  // Credentials are made for some days (--days): an expired one is the likeliest failure.
  const auto when = [](const ASN1_TIME* t) {
    Bio b(BIO_new(BIO_s_mem()));
    ASN1_TIME_print(b.get(), t);
    char* text = nullptr;
    const long n = BIO_get_mem_data(b.get(), &text);
    return std::string(text, static_cast<size_t>(std::max(n, 0L)));
  };
  if (X509_cmp_current_time(X509_get0_notAfter(c.get())) < 0)
    throw std::runtime_error(file.string() + ": expired on " + when(X509_get0_notAfter(c.get())) +
                             " (make the credentials again: simsoccer credentials DIR --days N)");
  if (X509_cmp_current_time(X509_get0_notBefore(c.get())) > 0)
    throw std::runtime_error(file.string() + ": not valid before " +
                             when(X509_get0_notBefore(c.get())));
  return c;
}

// An S/MIME document signed by `ca` alone (the signer looked up among {ca} only).
void checkSigned(const std::filesystem::path& file, X509* ca) {
  BIO* content = nullptr;
  Pkcs7 p7(SMIME_read_PKCS7(readFile(file).get(), &content));
  Bio content_owner(content);
  if (!p7) fail(file.string() + ": not an S/MIME signed document");
  struct FreeStack {  // sk_X509_free is a macro
    void operator()(STACK_OF(X509) * s) const { sk_X509_free(s); }
  };
  std::unique_ptr<STACK_OF(X509), FreeStack> signers(sk_X509_new_null());
  sk_X509_push(signers.get(), ca);
  if (PKCS7_verify(p7.get(), signers.get(), nullptr, content, nullptr,
                   PKCS7_TEXT | PKCS7_NOINTERN | PKCS7_NOVERIFY) != 1)
    fail(file.string() + ": not signed by this folder's ca.pem");
}

}  // namespace

void checkMatchCredentials(const std::filesystem::path& given) {
  const std::filesystem::path dir = std::filesystem::absolute(given);
  const Cert ca = readCert(dir / "ca.pem");
  EVP_PKEY* ca_public = X509_get0_pubkey(ca.get());
  checkSigned(dir / "governance.p7s", ca.get());
  for (const std::string& id : credentialIdentities()) {
    const std::filesystem::path cert_file = dir / (id + ".pem"), key_file = dir / (id + "_key.pem");
    const Cert cert = readCert(cert_file);
    if (X509_verify(cert.get(), ca_public) != 1)
      fail(cert_file.string() + ": not signed by this folder's ca.pem");
    const Key key(PEM_read_bio_PrivateKey(readFile(key_file).get(), nullptr, nullptr, nullptr));
    if (!key) fail(key_file.string() + ": not a PEM private key");
    if (X509_check_private_key(cert.get(), key.get()) != 1)
      fail(key_file.string() + ": not the key of " + cert_file.string());
    checkSigned(dir / (id + "_permissions.p7s"), ca.get());
    // The configuration names its files by absolute path: a folder copied elsewhere still
    // names the original's.
    std::ifstream in(credentialConfig(dir, id));
    std::stringstream xml;
    xml << in.rdbuf();
    const std::string named = "<IdentityCA>file:";
    const size_t at = xml.str().find(named);
    if (!in || at == std::string::npos)
      throw std::runtime_error(credentialConfig(dir, id).string() +
                               ": no <IdentityCA>file:...</IdentityCA> (not written by "
                               "`simsoccer credentials`?)");
    const size_t start = at + named.size(), end = xml.str().find("</IdentityCA>", start);
    const std::filesystem::path ca_named = xml.str().substr(start, end - start);
    std::error_code ec;
    if (!std::filesystem::equivalent(ca_named, dir / "ca.pem", ec))
      throw std::runtime_error(credentialConfig(dir, id).string() + ": names " + ca_named.string() +
                               ", not this folder's ca.pem (the folder was "
                               "copied or moved: make the credentials here again)");
  }
}

}  // namespace simsoccer::net
