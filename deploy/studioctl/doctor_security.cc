#include "studioctl/doctor_security.h"

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <optional>
#include <regex>
#include <set>

namespace studio::ctl {

namespace {

const char kMakePki[] =
    "make the PKI with deploy/security/make-pki --out DIR (installed in "
    "/usr/share/studio/security/) and point STUDIO_SECURITY_DIR at DIR and STUDIO_IDENTITY at the "
    "service's identity (DIR/identities/NAME), or fix the path in the profile";

template <class T, void (*F)(T*)>
struct Free {
  void operator()(T* p) const { F(p); }
};
using Bio = std::unique_ptr<BIO, Free<BIO, BIO_free_all>>;
using Cert = std::unique_ptr<X509, Free<X509, X509_free>>;
using Key = std::unique_ptr<EVP_PKEY, Free<EVP_PKEY, EVP_PKEY_free>>;
using Store = std::unique_ptr<X509_STORE, Free<X509_STORE, X509_STORE_free>>;
using Pkcs7 = std::unique_ptr<PKCS7, Free<PKCS7, PKCS7_free>>;

std::string openssl_error() {
  const unsigned long e = ERR_get_error();
  ERR_clear_error();
  if (e == 0) return "unknown OpenSSL error";
  char buf[256];
  ERR_error_string_n(e, buf, sizeof buf);
  return buf;
}

std::string text_of(const ASN1_TIME* t) {
  Bio b(BIO_new(BIO_s_mem()));
  ASN1_TIME_print(b.get(), t);
  char* data = nullptr;
  const long n = BIO_get_mem_data(b.get(), &data);
  return std::string(data, size_t(n));
}

std::string subject_of(const X509* c) {
  Bio b(BIO_new(BIO_s_mem()));
  X509_NAME_print_ex(b.get(), X509_get_subject_name(c), 0, XN_FLAG_RFC2253);
  char* data = nullptr;
  const long n = BIO_get_mem_data(b.get(), &data);
  return std::string(data, size_t(n));
}

// "CN=a,O=b" -> {"CN=a", "O=b"} (whitespace around parts dropped): DN parts in any order.
std::set<std::string> dn_parts(const std::string& dn) {
  std::set<std::string> out;
  std::string cur;
  auto flush = [&] {
    const auto a = cur.find_first_not_of(" \t\n"), b = cur.find_last_not_of(" \t\n");
    if (a != std::string::npos) out.insert(cur.substr(a, b - a + 1));
    cur.clear();
  };
  for (char c : dn) {
    if (c == ',')
      flush();
    else
      cur += c;
  }
  flush();
  return out;
}

Cert load_cert(const std::string& path) {
  Bio b(BIO_new_file(path.c_str(), "r"));
  if (!b) return nullptr;
  return Cert(PEM_read_bio_X509(b.get(), nullptr, nullptr, nullptr));
}

// A value of the profile: "file:/x" or "file:///x" -> "/x"; "data:..." -> "" (inline).
std::string file_of(const std::string& value) {
  std::string v = expand_env(value);
  const auto a = v.find_first_not_of(" \t\n"), b = v.find_last_not_of(" \t\n");
  v = a == std::string::npos ? "" : v.substr(a, b - a + 1);
  if (v.starts_with("data:")) return "";
  if (v.starts_with("file://")) return v.substr(7);
  if (v.starts_with("file:")) return v.substr(5);
  return v;
}

std::string element(const std::string& xml, const std::string& tag) {
  std::smatch m;
  if (std::regex_search(xml, m, std::regex("<" + tag + R"(\s*>([^<]*)</)" + tag + R"(\s*>)")))
    return m[1];
  return "";
}

void add(std::string& list, const std::string& item) { list += (list.empty() ? "" : "; ") + item; }

// Not-yet-valid / expired, as one phrase, or "" when valid now.
std::string validity_problem(const X509* c, const std::string& what) {
  if (X509_cmp_current_time(X509_get0_notAfter(c)) <= 0)
    return what + " expired on " + text_of(X509_get0_notAfter(c));
  if (X509_cmp_current_time(X509_get0_notBefore(c)) >= 0)
    return what + " is not valid before " + text_of(X509_get0_notBefore(c));
  return "";
}

// Verifies an S/MIME document against `ca`; returns its signed content, or nullopt + why.
std::optional<std::string> verify_smime(const std::string& path, X509* ca, std::string* why) {
  Bio in(BIO_new_file(path.c_str(), "r"));
  if (!in) {
    *why = "cannot be read";
    return std::nullopt;
  }
  BIO* content_raw = nullptr;
  Pkcs7 p7(SMIME_read_PKCS7(in.get(), &content_raw));
  Bio content(content_raw);
  if (!p7) {
    *why = "is not an S/MIME document (" + openssl_error() + ")";
    return std::nullopt;
  }
  Store store(X509_STORE_new());
  X509_STORE_add_cert(store.get(), ca);
  Bio out(BIO_new(BIO_s_mem()));
  if (PKCS7_verify(p7.get(), nullptr, store.get(), content.get(), out.get(), PKCS7_TEXT) != 1) {
    *why = "is not signed by the permissions CA (" + openssl_error() + ")";
    return std::nullopt;
  }
  char* data = nullptr;
  const long n = BIO_get_mem_data(out.get(), &data);
  return std::string(data, size_t(n));
}

time_t parse_xml_time(const std::string& s) {  // CCYY-MM-DDThh:mm:ss[Z]
  std::tm tm{};
  if (!strptime(s.c_str(), "%Y-%m-%dT%H:%M:%S", &tm)) return -1;
  return timegm(&tm);
}

}  // namespace

std::string expand_env(const std::string& text) {
  static const std::regex var(R"(\$\{([A-Za-z_][A-Za-z0-9_]*)(:-([^}]*))?\})");
  std::string out;
  auto begin = text.cbegin();
  for (auto it = std::sregex_iterator(text.begin(), text.end(), var); it != std::sregex_iterator();
       ++it) {
    out.append(begin, text.cbegin() + it->position());
    const char* v = std::getenv((*it)[1].str().c_str());
    if (v && *v)
      out += v;
    else if ((*it)[2].matched)
      out += (*it)[3].str();
    begin = text.cbegin() + it->position() + it->length();
  }
  out.append(begin, text.cend());
  return out;
}

std::vector<SecurityCheck> security_checks(const std::string& xml) {
  std::smatch m;
  if (!std::regex_search(xml, m, std::regex(R"(<Security\b[^>]*>([\s\S]*?)</Security\s*>)")))
    return {
        {"security", "warn", "the profile configures no DDS Security: the domain is not secured",
         "append the secure profile: CYCLONEDDS_URI=...,file:///usr/share/studio/dds/secure.xml "
         "(deploy/security/README.md)"}};
  const std::string sec = m[1];
  std::vector<SecurityCheck> checks;

  // Files: the plugins and every document, readable by this user.
  struct Named {
    std::string what, path;
  };
  std::vector<Named> files;
  const std::regex lib(
      R"(<(Authentication|AccessControl|Cryptographic)\b[\s\S]*?<Library\b[^>]*\bpath\s*=\s*"([^"]*)\")");
  for (auto it = std::sregex_iterator(sec.begin(), sec.end(), lib); it != std::sregex_iterator();
       ++it)
    files.push_back({(*it)[1].str() + " plugin", expand_env((*it)[2])});
  for (const char* tag : {"IdentityCA", "IdentityCertificate", "PrivateKey", "PermissionsCA",
                          "Governance", "Permissions"})
    files.push_back({tag, file_of(element(sec, tag))});
  std::string problems, fix;
  bool identity_unset = false;
  for (const auto& f : files) {
    if (f.path.empty()) {
      if (f.what.find("plugin") == std::string::npos && element(sec, f.what).empty())
        add(problems, f.what + " is not configured");
      continue;  // inline data: nothing on disk to check
    }
    if (f.path.find("identities//") != std::string::npos) identity_unset = true;
    if (f.path[0] != '/' && f.what.find("plugin") != std::string::npos) continue;  // loader's path
    if (::access(f.path.c_str(), R_OK) != 0)
      add(problems, f.what + " " + f.path + ": " + std::strerror(errno));
  }
  if (identity_unset)
    fix = "set STUDIO_IDENTITY to this service's identity (its folder under identities/); ";
  if (!problems.empty()) {
    bool plugin = problems.find("plugin") != std::string::npos;
    fix += plugin ? "install libddsc0debian (the plugins) or fix the Library path; " : "";
    fix += kMakePki;
    checks.push_back({"security_files", "fail", problems, fix});
    return checks;  // the checks below need the files
  }
  checks.push_back({"security_files", "ok",
                    "security plugins and documents readable: " +
                        file_of(element(sec, "IdentityCertificate")) + " ...",
                    ""});

  // Certificates: valid now, the identity signed by the identity CA, the key is the identity's.
  const std::string id_ca_path = file_of(element(sec, "IdentityCA")),
                    cert_path = file_of(element(sec, "IdentityCertificate")),
                    key_path = file_of(element(sec, "PrivateKey")),
                    perm_ca_path = file_of(element(sec, "PermissionsCA"));
  Cert id_ca = load_cert(id_ca_path), cert = load_cert(cert_path),
       perm_ca = load_cert(perm_ca_path);
  problems.clear();
  fix.clear();
  if (!id_ca) add(problems, "IdentityCA " + id_ca_path + " is not a PEM certificate");
  if (!cert) add(problems, "IdentityCertificate " + cert_path + " is not a PEM certificate");
  if (!perm_ca) add(problems, "PermissionsCA " + perm_ca_path + " is not a PEM certificate");
  std::string subject;
  if (id_ca && cert) {
    subject = subject_of(cert.get());
    if (auto p = validity_problem(cert.get(), "the identity certificate " + cert_path);
        !p.empty()) {
      add(problems, p);
      add(fix, "issue a new identity: make-pki --out DIR --identity NAME --force");
    }
    if (auto p = validity_problem(id_ca.get(), "the identity CA " + id_ca_path); !p.empty()) {
      add(problems, p);
      add(fix, "make a new CA and identities for every host (make-pki --out NEW_DIR)");
    }
    if (X509_verify(cert.get(), X509_get0_pubkey(id_ca.get())) != 1) {
      ERR_clear_error();
      add(problems, "the identity certificate " + cert_path + " (" + subject +
                        ") is not signed by the identity CA " + id_ca_path + " (" +
                        subject_of(id_ca.get()) + ")");
      add(fix,
          "use the CA of the PKI that issued the identity, or issue the identity from this CA");
    }
    Bio kb(BIO_new_file(key_path.c_str(), "r"));
    Key key(kb ? PEM_read_bio_PrivateKey(kb.get(), nullptr, nullptr, nullptr) : nullptr);
    if (!key || X509_check_private_key(cert.get(), key.get()) != 1) {
      ERR_clear_error();
      add(problems, "the private key " + key_path + " does not belong to " + cert_path);
      add(fix, "keep cert.pem and key.pem of one identity together (make-pki writes both)");
    }
  }
  if (perm_ca)
    if (auto p = validity_problem(perm_ca.get(), "the permissions CA " + perm_ca_path); !p.empty())
      add(problems, p);
  checks.push_back(problems.empty()
                       ? SecurityCheck{"security_certificates", "ok",
                                       "identity " + subject + " valid until " +
                                           text_of(X509_get0_notAfter(cert.get())) +
                                           ", signed by the identity CA",
                                       ""}
                       : SecurityCheck{"security_certificates", "fail", problems, fix});

  // Documents: governance and permissions signed by the permissions CA; the permissions grant
  // the identity's subject and are valid now.
  problems.clear();
  fix.clear();
  if (perm_ca) {
    std::string why;
    const std::string gov = file_of(element(sec, "Governance")),
                      perms = file_of(element(sec, "Permissions"));
    if (!verify_smime(gov, perm_ca.get(), &why)) add(problems, "the governance " + gov + " " + why);
    if (auto content = verify_smime(perms, perm_ca.get(), &why); !content) {
      add(problems, "the permissions " + perms + " " + why);
    } else if (cert) {
      const std::string granted = element(*content, "subject_name");
      if (dn_parts(granted) != dn_parts(subject))
        add(problems, "the permissions " + perms + " grant '" + granted +
                          "', not the identity's subject '" + subject + "'");
      const time_t after = parse_xml_time(element(*content, "not_after"));
      if (after >= 0 && after < std::time(nullptr))
        add(problems, "the permissions " + perms + " expired on " + element(*content, "not_after"));
    }
    if (!problems.empty())
      fix =
          "sign the documents with the PKI's CA: make-pki --out DIR (governance) and "
          "make-pki --out DIR --identity NAME --force (permissions)";
  } else {
    add(problems, "no permissions CA to verify the governance and permissions with");
    fix = kMakePki;
  }
  checks.push_back(problems.empty()
                       ? SecurityCheck{"security_documents", "ok",
                                       "governance and permissions signed by the permissions CA",
                                       ""}
                       : SecurityCheck{"security_documents", "fail", problems, fix});
  return checks;
}

}  // namespace studio::ctl
