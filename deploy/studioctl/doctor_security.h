#pragma once
// studioctl doctor's DDS Security checks (issue 19 items 3-4): the files the profile's
// <Security> section names (deploy/dds/secure.xml with $STUDIO_SECURITY_DIR / $STUDIO_IDENTITY,
// or literal paths) exist and can be read by this user, the certificates are valid now and signed
// by the CA the profile names, the private key belongs to the certificate, and the governance and
// permissions documents are S/MIME signed by the permissions CA.

#include <string>
#include <vector>

namespace studio::ctl {

struct SecurityCheck {
  std::string name, status, message, fix;  // status: ok | warn | fail
};

// `xml`: the profile (every file and fragment of the URI, comments stripped). Cyclone's
// ${VAR}, ${VAR:-default} references are expanded from this process's environment, as Cyclone
// expands them. Without a <Security> section: one check "security" (warn: the domain is not
// secured). Otherwise: security_files, security_certificates, security_documents.
std::vector<SecurityCheck> security_checks(const std::string& xml);

// Cyclone's expansion of ${VAR} and ${VAR:-default} (unset or empty -> default, else "").
std::string expand_env(const std::string& text);

}  // namespace studio::ctl
