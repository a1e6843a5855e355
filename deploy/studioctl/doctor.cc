#include "studioctl/doctor.h"

#include <arpa/inet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/timex.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "studioctl/cli.h"
#include "studioctl/discovery.h"
#include "studioctl/doctor_security.h"
#include "studioctl/printer.h"

namespace studio::ctl {

const char kDoctorHelp[] =
    "usage: studioctl doctor [--wait S] [--json]\n"
    "\n"
    "Checks this host against the DDS profile the services use (--dds-config FILE, else\n"
    "$CYCLONEDDS_URI) and says what to fix:\n"
    "  profile         every file of the URI can be read\n"
    "  interfaces      each interface the profile names exists, is up and can multicast (or the\n"
    "                  profile forces multicast on it); with auto-detection, some interface\n"
    "                  besides lo is up and multicast-capable\n"
    "  socket_buffers  the receive/send buffer minimum the profile asks for fits\n"
    "                  net.core.rmem_max / wmem_max (Cyclone refuses to start otherwise)\n"
    "  multicast_route the kernel routes the discovery group 239.255.0.1 and the profile's\n"
    "                  partition groups (needed unless the profile names the interface)\n"
    "  clock           the system clock is synchronised (adjtimex; frame numbers are computed\n"
    "                  from it on every host, DESIGN §5): a warning, not a failure\n"
    "  participant     a participant can join the domain; how many peers it discovers (--wait S,\n"
    "                  default 1)\n"
    "  security_*      with DDS Security in the profile (doctor_security.h): the plugins and "
    "files\n"
    "                  it names exist and are readable; the identity certificate and the CAs are\n"
    "                  valid now, the identity is signed by the identity CA and matches its key;\n"
    "                  governance and permissions are signed by the permissions CA and grant the\n"
    "                  identity (${VAR} in the profile expanded as Cyclone does); without it, a\n"
    "                  warning that the domain is not secured\n"
    "Output: one line per check (ok / warn / FAIL, what, and the fix); --json: one object per\n"
    "check per line {check, status, message, fix}. Exit 1 when a check FAILs, else 0.\n";

namespace {

struct Check {
  std::string name, status, message, fix;  // status: ok | warn | fail
};

std::string slurp(const std::string& path, bool* ok) {
  std::ifstream in(path);
  *ok = bool(in);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Bytes of a Cyclone size ("8MB", "1 MiB", "65500B", "4096").
uint64_t parse_size(const std::string& text) {
  std::smatch m;
  const std::regex re(R"(^\s*([0-9.]+)\s*([kKMG]i?B|B)?\s*$)");
  if (!std::regex_match(text, m, re)) return 0;
  double v = std::atof(m[1].str().c_str());
  const std::string u = m[2].matched ? m[2].str() : "B";
  const bool binary = u.size() == 3;
  const double k = binary ? 1024.0 : 1000.0;
  if (u[0] == 'k' || u[0] == 'K') v *= k;
  if (u[0] == 'M') v *= k * k;
  if (u[0] == 'G') v *= k * k * k;
  return uint64_t(v);
}

uint64_t read_sysctl(const char* path) {
  std::ifstream in(path);
  uint64_t v = 0;
  in >> v;
  return v;
}

unsigned interface_flags(const std::string& name, bool* exists) {
  std::ifstream in("/sys/class/net/" + name + "/flags");
  *exists = bool(in);
  unsigned flags = 0;
  in >> std::hex >> flags;
  return flags;
}

std::vector<std::string> interfaces() {
  std::vector<std::string> out;
  if (auto* ni = if_nameindex()) {
    for (auto* i = ni; i->if_index != 0; ++i) out.push_back(i->if_name);
    if_freenameindex(ni);
  }
  return out;
}

bool routes_multicast(const std::string& group) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(7400);
  inet_pton(AF_INET, group.c_str(), &a.sin_addr);
  const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return ok;
}

}  // namespace

int doctor_command(const std::vector<std::string>& argv) {
  auto a = parse_args(argv, {"--wait"});
  if (!a) return complain("doctor", a.error().message, 2);
  if (a->help) {
    std::fputs(kDoctorHelp, stdout);
    return 0;
  }
  if (!a->positional.empty())
    return complain("doctor", "unexpected argument '" + a->positional[0] + "'", 2);
  auto wait = seconds_flag(*a, "--wait", 1.0, 0.1, 60);
  if (!wait) return complain("doctor", wait.error().message, 2);
  std::vector<Check> checks;

  // profile: the URI's files and inline fragments, concatenated.
  std::string uri = a->common.dds_config;
  if (uri.empty() && std::getenv("CYCLONEDDS_URI")) uri = std::getenv("CYCLONEDDS_URI");
  std::string xml;
  {
    Check c{"profile", "ok", "", ""};
    if (uri.empty()) {
      c = {"profile", "warn",
           "no DDS profile: neither --dds-config nor $CYCLONEDDS_URI is set (Cyclone's defaults)",
           "set CYCLONEDDS_URI=file:///etc/studio/dds.xml as the units do"};
    } else {
      std::vector<std::string> parts;
      std::string cur;
      int depth = 0;
      for (char ch : uri) {  // split on commas outside XML elements
        if (ch == '<') ++depth;
        if (ch == '>') --depth;
        if (ch == ',' && depth == 0) {
          parts.push_back(cur);
          cur.clear();
        } else {
          cur += ch;
        }
      }
      parts.push_back(cur);
      for (auto p : parts) {
        p.erase(0, p.find_first_not_of(" \t\n"));
        if (p.starts_with("file://")) p = p.substr(7);
        if (p.empty()) continue;
        if (p[0] == '<') {
          xml += p;
          continue;
        }
        bool ok = false;
        xml += slurp(p, &ok);
        if (!ok) {
          c = {"profile", "fail",
               "the DDS profile " + p + " cannot be read: " + std::strerror(errno),
               "install it (cmake --install puts the production profile in /etc/studio/dds.xml) or "
               "fix CYCLONEDDS_URI"};
          break;
        }
      }
      if (c.status == "ok") c.message = "DDS profile: " + uri;
      xml = std::regex_replace(xml, std::regex(R"(<!--[\s\S]*?-->)"), "");  // comments say nothing
    }
    checks.push_back(c);
  }

  // interfaces
  {
    std::smatch m;
    const std::regex named(R"(<NetworkInterface\b([^>]*)>)");
    std::vector<std::pair<std::string, bool>> wanted;  // name, multicast forced
    bool autodetect = xml.find("<NetworkInterface") == std::string::npos;
    for (auto it = std::sregex_iterator(xml.begin(), xml.end(), named);
         it != std::sregex_iterator(); ++it) {
      const std::string attrs = (*it)[1];
      std::smatch n;
      if (std::regex_search(attrs, n, std::regex(R"(\bname\s*=\s*"([^"]+)\")")))
        wanted.emplace_back(n[1], attrs.find("multicast=\"true\"") != std::string::npos);
      else if (attrs.find("autodetermine=\"true\"") != std::string::npos)
        autodetect = true;
    }
    Check c{"interfaces", "ok", "", ""};
    // A unicast profile (AllowMulticast false) needs interfaces that are up, nothing more.
    const bool unicast = std::regex_search(xml, std::regex(R"(<AllowMulticast>\s*false\s*<)"));
    std::string problems, fine;
    for (const auto& [name, forced] : wanted) {
      bool exists = false;
      const unsigned flags = interface_flags(name, &exists);
      if (!exists)
        problems += name + " does not exist; ";
      else if (!(flags & IFF_UP))
        problems += name + " is down; ";
      else if (!(flags & IFF_MULTICAST) && !forced && !unicast)
        problems += name + " cannot multicast; ";
      else
        fine += (fine.empty() ? "" : ", ") + name;
    }
    if (autodetect) {
      std::string usable;
      for (const auto& name : interfaces()) {
        bool exists = false;
        const unsigned flags = interface_flags(name, &exists);
        if (name != "lo" && (flags & IFF_UP) && ((flags & IFF_MULTICAST) || unicast))
          usable += (usable.empty() ? "" : ", ") + name;
      }
      if (usable.empty())
        problems += unicast ? "auto-detection finds no interface besides lo that is up; "
                            : "auto-detection finds no interface besides lo that is up and "
                              "multicast-capable; ";
      else
        fine += (fine.empty() ? "" : ", ") + std::string("auto-detected among ") + usable;
    }
    if (!problems.empty()) {
      problems.resize(problems.size() - 2);
      std::string present;
      for (const auto& n : interfaces()) present += (present.empty() ? "" : ", ") + n;
      c = {
          "interfaces", "fail", problems + " (this host has: " + present + ")",
          "name the studio interface in the profile (<NetworkInterface name=\"IF\"/>), bring it up "
          "(ip link set IF up) and enable multicast (ip link set IF multicast on)"};
    } else {
      c.message = "interfaces: " + fine;
    }
    checks.push_back(c);
  }

  // socket buffers
  {
    Check c{"socket_buffers", "ok", "", ""};
    std::smatch m;
    for (const auto& [tag, sysctl, name] :
         {std::tuple{"SocketReceiveBufferSize", "/proc/sys/net/core/rmem_max", "net.core.rmem_max"},
          std::tuple{"SocketSendBufferSize", "/proc/sys/net/core/wmem_max", "net.core.wmem_max"}}) {
      const std::regex re(std::string("<") + tag + R"([^>]*\bmin\s*=\s*"([^"]+)\")");
      const uint64_t limit = read_sysctl(sysctl);
      if (!std::regex_search(xml, m, re)) {
        c.message += std::string(c.message.empty() ? "" : "; ") + name + " = " +
                     std::to_string(limit) + " (profile asks no minimum)";
        continue;
      }
      const uint64_t want = parse_size(m[1]);
      if (want > limit) {
        c.status = "fail";
        c.message += std::string(c.message.empty() ? "" : "; ") + "the profile asks for " + tag +
                     " min " + m[1].str() + " (" + std::to_string(want) + " bytes) but " + name +
                     " = " + std::to_string(limit) +
                     " (the services run without CAP_NET_ADMIN: the kernel limit applies)";
        c.fix += std::string(c.fix.empty() ? "" : "; ") + "sysctl -w " + name + "=" +
                 std::to_string(want) + " (and in /etc/sysctl.d/90-studio.conf)";
      } else {
        c.message += std::string(c.message.empty() ? "" : "; ") + name + " = " +
                     std::to_string(limit) + " >= " + m[1].str();
      }
    }
    checks.push_back(c);
  }

  // multicast routes
  {
    std::set<std::string> groups{"239.255.0.1"};
    const std::regex addr(R"(<NetworkPartition\b[^>]*\bAddress\s*=\s*"([0-9.]+)\")");
    for (auto it = std::sregex_iterator(xml.begin(), xml.end(), addr); it != std::sregex_iterator();
         ++it)
      groups.insert((*it)[1]);
    const bool multicast_off =
        std::regex_search(xml, std::regex(R"(<AllowMulticast>\s*false\s*<)"));
    const bool named = std::regex_search(xml, std::regex(R"(<NetworkInterface\b[^>]*\bname\s*=)"));
    std::string missing;
    for (const auto& g : groups)
      if (!routes_multicast(g)) missing += (missing.empty() ? "" : ", ") + g;
    Check c{"multicast_route", "ok",
            "routes to " + std::to_string(groups.size()) + " multicast group(s)", ""};
    if (multicast_off) {
      c.message = "multicast is off in the profile (AllowMulticast false): unicast discovery only";
    } else if (!missing.empty()) {
      c = {"multicast_route", named ? "warn" : "fail",
           "no route to the multicast group(s) " + missing,
           "ip route add 224.0.0.0/4 dev IF (the studio interface), or name the interface in the "
           "profile"};
    }
    checks.push_back(c);
  }

  // clock
  {
    timex t{};
    const int state = adjtimex(&t);
    Check c{"clock", "ok", "the system clock is synchronised", ""};
    if (state == TIME_ERROR || (t.status & STA_UNSYNC))
      c = {"clock", "warn", "the system clock is not synchronised (adjtimex reports TIME_ERROR)",
           "run PTP (ptp4l + phc2sys) or chrony against the studio's time source: every host "
           "numbers frames from its clock"};
    checks.push_back(c);
  }

  // DDS Security: the files the profile names (doctor_security.cc)
  for (auto& s : security_checks(xml)) checks.push_back({s.name, s.status, s.message, s.fix});

  // participant
  {
    Check c{"participant", "ok", "", ""};
    auto p = open_participant(a->common);
    if (!p) {
      c = {"participant", "fail", "cannot join the DDS domain: " + p.error().message,
           "see the checks above; Cyclone's own log: "
           "CYCLONEDDS_URI=...,<Tracing><Verbosity>config</Verbosity><OutputFile>stderr</"
           "OutputFile></Tracing>"};
    } else {
      auto eps = discover(*p, to_ns(*wait));
      std::set<std::string> hosts;
      std::set<int> pids;
      if (eps)
        for (const auto& e : *eps) {
          hosts.insert(e.host);
          pids.insert(e.pid);
        }
      c.message = "joined the domain; " + std::to_string(pids.size()) + " peer process(es) on " +
                  std::to_string(hosts.size()) + " host(s) discovered within " +
                  std::to_string(*wait).substr(0, 3) + " s";
    }
    checks.push_back(c);
  }

  bool failed = false;
  for (const auto& c : checks) {
    failed = failed || c.status == "fail";
    if (a->common.json) {
      Printer pr(Printer::Mode::json);
      pr.begin_object();
      pr.key("check");
      pr.string(c.name);
      pr.key("status");
      pr.string(c.status);
      pr.key("message");
      pr.string(c.message);
      pr.key("fix");
      pr.string(c.fix);
      pr.end_object();
      emit(pr.take());
    } else {
      const char* tag = c.status == "ok" ? "ok  " : c.status == "warn" ? "warn" : "FAIL";
      emit(std::string(tag) + " " + c.name + ": " + c.message +
           (c.fix.empty() ? "" : "\n     fix: " + c.fix));
    }
  }
  return failed ? 1 : 0;
}

}  // namespace studio::ctl
