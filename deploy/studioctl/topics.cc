#include "studioctl/topics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <set>

#include "studioctl/cli.h"
#include "studioctl/discovery.h"
#include "studioctl/topic_reader.h"

namespace studio::ctl {

const char kTopicHelp[] =
    "usage: studioctl topic list [--all] [--wait S] [--json]\n"
    "       studioctl topic info TOPIC [--wait S] [--json]\n"
    "       studioctl topic hz TOPIC [--window S] [--count N] [--json]\n"
    "       studioctl topic echo TOPIC [--count N] [--timeout S] [--key KEY] [--json]\n"
    "\n"
    "  list   topics seen on the domain (Cyclone's DCPSPublication/DCPSSubscription): name, type,\n"
    "         writer and reader counts, hosts, and the QoS of the studio table for known topics.\n"
    "         --all adds the table's topics nobody uses yet. --wait S: discovery time (default "
    "2).\n"
    "  info   the table's QoS for TOPIC, and every writer and reader: host, pid, process, QoS.\n"
    "  hz     arrival rate of TOPIC every second over the last --window S seconds (default 10):\n"
    "         mean rate, min/max/std dev of the inter-arrival time, and the rate per instance\n"
    "         (key). --count N: stop after N reports.\n"
    "  echo   every sample of TOPIC as text (long arrays summarised), or with --json one JSON\n"
    "         object per sample per line with the IDL's member names (arrays in full, enums by\n"
    "         name). --count N: stop after N samples; --timeout S: fail (exit 1) when fewer\n"
    "         arrived within S seconds; --key KEY: only the instance whose @key members, joined\n"
    "         by '/', are KEY (e.g. cam0, or capture/cam0 for studio/service/status). Malformed\n"
    "         samples (the wire validators) are printed too, and reported on stderr.\n"
    "\n"
    "JSON output is one object per line. Common options: --domain N, --dds-config FILE\n"
    "(default $STUDIO_DDS_DOMAIN, $CYCLONEDDS_URI), --json, --help.\n";

namespace {

struct TopicSummary {
  std::string type;
  int writers = 0, readers = 0;
  std::set<std::string> hosts;
};

void json_qos(Printer& p, const wire::TopicRow& row) {
  p.key("qos");
  p.begin_object();
  p.key("reliability");
  p.string(row.reliable ? "reliable" : "best-effort");
  p.key("durability");
  p.string(row.transient_local ? "transient-local" : "volatile");
  p.key("depth");
  p.number(int64_t(row.depth));
  p.key("liveliness_lease_s");
  p.number(int64_t(row.liveliness_lease_s));
  p.end_object();
}

int list(const Args& a) {
  auto wait = seconds_flag(a, "--wait", 2.0, 0.1, 60);
  if (!wait) return complain("topic list", wait.error().message, 2);
  auto p = open_participant(a.common);
  if (!p) return complain("topic list", p.error().message);
  auto endpoints = discover(*p, to_ns(*wait));
  if (!endpoints) return complain("topic list", endpoints.error().message);
  std::map<std::string, TopicSummary> topics;
  for (const auto& e : *endpoints) {
    auto& t = topics[e.topic];
    t.type = e.type;
    (e.writer ? t.writers : t.readers)++;
    if (!e.host.empty()) t.hosts.insert(e.host);
  }
  if (a.has("--all"))
    for (const auto& row : wire::topic_table())
      if (!topics.contains(row.name)) topics[row.name].type = row.descriptor->m_typename;

  if (topics.empty() && !a.common.json)
    std::fprintf(
        stderr,
        "studioctl topic list: no topic seen within %.1f s (--all lists the studio table)\n",
        *wait);
  if (!a.common.json)
    std::printf("%-32s %-28s %3s %3s  %-16s %s\n", "TOPIC", "TYPE", "W", "R", "HOSTS",
                "QOS (studio table)");
  for (const auto& [name, t] : topics) {
    const wire::TopicRow* row = find_topic(name);
    std::string hosts;
    for (const auto& h : t.hosts) hosts += (hosts.empty() ? "" : ",") + h;
    if (a.common.json) {
      Printer pr(Printer::Mode::json);
      pr.begin_object();
      pr.key("topic");
      pr.string(name);
      pr.key("type");
      pr.string(t.type);
      pr.key("writers");
      pr.number(int64_t(t.writers));
      pr.key("readers");
      pr.number(int64_t(t.readers));
      pr.key("hosts");
      pr.begin_array(t.hosts.size(), false);
      for (const auto& h : t.hosts) {
        pr.element();
        pr.string(h);
      }
      pr.end_array(t.hosts.size(), t.hosts.size());
      pr.key("known");
      pr.number(row != nullptr);
      if (row) json_qos(pr, *row);
      pr.end_object();
      emit(pr.take());
    } else {
      std::printf("%-32s %-28s %3d %3d  %-16s %s\n", name.c_str(), t.type.c_str(), t.writers,
                  t.readers, hosts.empty() ? "-" : hosts.c_str(),
                  row ? qos_text(*row).c_str() : "(not in the studio table)");
    }
  }
  std::fflush(stdout);
  return 0;
}

int info(const Args& a) {
  if (a.positional.size() != 1) return complain("topic info", "name one TOPIC (see --help)", 2);
  const std::string& name = a.positional[0];
  const wire::TopicRow* row = find_topic(name);
  auto wait = seconds_flag(a, "--wait", 2.0, 0.1, 60);
  if (!wait) return complain("topic info", wait.error().message, 2);
  auto p = open_participant(a.common);
  if (!p) return complain("topic info", p.error().message);
  auto endpoints = discover(*p, to_ns(*wait));
  if (!endpoints) return complain("topic info", endpoints.error().message);
  std::vector<Endpoint> mine;
  for (auto& e : *endpoints)
    if (e.topic == name) mine.push_back(e);
  if (!row && mine.empty())
    return complain("topic info", "unknown topic '" + name +
                                      "': not in the studio table and not seen on the domain");

  if (a.common.json) {
    Printer pr(Printer::Mode::json);
    pr.begin_object();
    pr.key("topic");
    pr.string(name);
    pr.key("type");
    pr.string(row ? std::string(row->descriptor->m_typename) : mine.front().type);
    pr.key("known");
    pr.number(row != nullptr);
    if (row) json_qos(pr, *row);
    for (bool writers : {true, false}) {
      std::vector<const Endpoint*> list;
      for (const auto& e : mine)
        if (e.writer == writers) list.push_back(&e);
      pr.key(writers ? "writers" : "readers");
      pr.begin_array(list.size(), true);
      for (const auto* e : list) {
        pr.element();
        pr.begin_object();
        pr.key("host");
        pr.string(e->host);
        pr.key("pid");
        pr.number(int64_t(e->pid));
        pr.key("process");
        pr.string(e->process);
        pr.key("reliability");
        pr.string(e->reliability);
        pr.key("durability");
        pr.string(e->durability);
        pr.end_object();
      }
      pr.end_array(list.size(), list.size());
    }
    pr.end_object();
    emit(pr.take());
    return 0;
  }
  std::printf("topic: %s\ntype:  %s\n", name.c_str(),
              row ? row->descriptor->m_typename : mine.front().type.c_str());
  std::printf("qos:   %s\n", row ? qos_text(*row).c_str() : "(not in the studio table)");
  for (bool writers : {true, false}) {
    int n = 0;
    for (const auto& e : mine) n += e.writer == writers;
    std::printf("%s: %d\n", writers ? "writers" : "readers", n);
    for (const auto& e : mine)
      if (e.writer == writers)
        std::printf("  %s pid %d (%s): %s, %s\n", e.host.empty() ? "?" : e.host.c_str(), e.pid,
                    e.process.c_str(), e.reliability.c_str(), e.durability.c_str());
  }
  return 0;
}

Expected<TopicReader> open_named(const Args& a, const char* what,
                                 std::optional<wire::Participant>& p) {
  if (a.positional.size() != 1) return fail("name one TOPIC (see --help)");
  const wire::TopicRow* row = find_topic(a.positional[0]);
  if (!row)
    return fail("unknown topic '" + a.positional[0] +
                "' (studioctl topic list --all shows the studio table)");
  auto part = open_participant(a.common);
  if (!part) return std::unexpected(part.error());
  p.emplace(std::move(*part));
  return TopicReader::open(*p, *row);
}

int echo(const Args& a) {
  auto count = count_flag(a, "--count", 0);
  if (!count) return complain("topic echo", count.error().message, 2);
  auto timeout = seconds_flag(a, "--timeout", 0, 0.1, 1e6);
  if (!timeout) return complain("topic echo", timeout.error().message, 2);
  const std::string* key = a.value("--key");
  std::optional<wire::Participant> p;
  auto reader = open_named(a, "topic echo", p);
  if (!reader)
    return complain("topic echo", reader.error().message, a.positional.size() == 1 ? 1 : 2);
  const auto deadline = std::chrono::steady_clock::now() + to_ns(*timeout);
  uint64_t printed = 0;
  while (*count == 0 || printed < *count) {
    auto left = std::chrono::nanoseconds(DDS_INFINITY);
    if (*timeout > 0) {
      left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline -
                                                                  std::chrono::steady_clock::now());
      if (left.count() <= 0)
        return complain("topic echo", "timed out after " + std::to_string(printed) + " of " +
                                          std::to_string(*count) + " samples on " +
                                          a.positional[0]);
    }
    auto n = reader->next(left, [&](const RawSample& s) {
      if (*count != 0 && printed >= *count) return;
      if (key && reader->type().key(s.data) != *key) return;
      if (s.rejected)
        std::fprintf(stderr, "studioctl topic echo: sample %s is malformed (%s)\n",
                     reader->type().key(s.data).c_str(),
                     std::string(wire::reject_name(*s.rejected)).c_str());
      std::string out = print_sample(reader->type(), s.data, a.common.json);
      if (a.common.json)
        emit(out);
      else
        emit(out + "---");
      ++printed;
    });
    if (!n) return complain("topic echo", n.error().message);
  }
  return 0;
}

int hz(const Args& a) {
  auto window = seconds_flag(a, "--window", 10, 0.5, 3600);
  if (!window) return complain("topic hz", window.error().message, 2);
  auto count = count_flag(a, "--count", 0);
  if (!count) return complain("topic hz", count.error().message, 2);
  std::optional<wire::Participant> p;
  auto reader = open_named(a, "topic hz", p);
  if (!reader)
    return complain("topic hz", reader.error().message, a.positional.size() == 1 ? 1 : 2);

  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  auto seconds = [&](clock::time_point t) { return std::chrono::duration<double>(t - t0).count(); };
  std::deque<double> arrivals;
  std::map<std::string, std::deque<double>> per_key;
  uint64_t reports = 0, total = 0;
  auto next_report = clock::now() + std::chrono::seconds(1);
  while (*count == 0 || reports < *count) {
    const auto left = std::max(next_report - clock::now(), clock::duration::zero());
    auto n = reader->next(std::chrono::duration_cast<std::chrono::nanoseconds>(left),
                          [&](const RawSample& s) {
                            const double t = seconds(clock::now());
                            arrivals.push_back(t);
                            per_key[reader->type().key(s.data)].push_back(t);
                            ++total;
                          });
    if (!n) return complain("topic hz", n.error().message);
    if (clock::now() < next_report) continue;
    next_report += std::chrono::seconds(1);
    ++reports;
    const double now = seconds(clock::now());
    auto trim = [&](std::deque<double>& d) {
      while (!d.empty() && d.front() < now - *window) d.pop_front();
    };
    trim(arrivals);
    double mean = 0, mn = 0, mx = 0, sd = 0;
    const std::size_t gaps = arrivals.size() > 1 ? arrivals.size() - 1 : 0;
    if (gaps > 0) {
      mn = 1e300;
      for (std::size_t i = 1; i < arrivals.size(); ++i) {
        const double d = arrivals[i] - arrivals[i - 1];
        mean += d;
        mn = std::min(mn, d);
        mx = std::max(mx, d);
      }
      mean /= double(gaps);
      for (std::size_t i = 1; i < arrivals.size(); ++i) {
        const double d = arrivals[i] - arrivals[i - 1] - mean;
        sd += d * d;
      }
      sd = std::sqrt(sd / double(gaps));
    }
    const double rate = gaps > 0 && mean > 0 ? 1.0 / mean : 0.0;
    std::vector<std::pair<std::string, double>> instances;
    for (auto it = per_key.begin(); it != per_key.end();) {
      trim(it->second);
      if (it->second.empty()) {
        it = per_key.erase(it);
        continue;
      }
      const auto& d = it->second;
      const double span = d.back() - d.front();
      instances.emplace_back(it->first,
                             d.size() > 1 && span > 0 ? double(d.size() - 1) / span : 0.0);
      ++it;
    }
    if (a.common.json) {
      Printer pr(Printer::Mode::json);
      pr.begin_object();
      pr.key("topic");
      pr.string(a.positional[0]);
      pr.key("rate_hz");
      pr.number(rate);
      pr.key("min_s");
      pr.number(mn);
      pr.key("max_s");
      pr.number(mx);
      pr.key("std_s");
      pr.number(sd);
      pr.key("window_samples");
      pr.number(uint64_t(arrivals.size()));
      pr.key("window_s");
      pr.number(std::min(*window, now));
      pr.key("total_samples");
      pr.number(total);
      pr.key("instances");
      pr.begin_object();
      for (const auto& [k, r] : instances) {
        pr.key(k);
        pr.number(r);
      }
      pr.end_object();
      pr.end_object();
      emit(pr.take());
    } else if (gaps == 0) {
      emit("no samples in the window" + std::string(arrivals.empty() ? "" : " (1 sample)"));
    } else {
      char line[256];
      std::snprintf(line, sizeof line,
                    "average rate: %.3f\n\tmin: %.3fs max: %.3fs std dev: %.5fs window: %zu", rate,
                    mn, mx, sd, arrivals.size());
      std::string out = line;
      if (instances.size() > 1)
        for (const auto& [k, r] : instances) {
          std::snprintf(line, sizeof line, "\n\t%s: %.3f Hz", k.c_str(), r);
          out += line;
        }
      emit(out);
    }
  }
  return 0;
}

}  // namespace

int topic_command(const std::vector<std::string>& argv) {
  if (argv.empty() || argv[0] == "--help" || argv[0] == "-h") {
    std::fputs(kTopicHelp, argv.empty() ? stderr : stdout);
    return argv.empty() ? 2 : 0;
  }
  const std::string verb = argv[0];
  const std::vector<std::string> rest(argv.begin() + 1, argv.end());
  Expected<Args> a = fail("");
  if (verb == "list")
    a = parse_args(rest, {"--wait"}, {"--all"});
  else if (verb == "info")
    a = parse_args(rest, {"--wait"});
  else if (verb == "echo")
    a = parse_args(rest, {"--count", "--timeout", "--key"});
  else if (verb == "hz")
    a = parse_args(rest, {"--window", "--count"});
  else
    return complain("topic", "unknown verb '" + verb + "' (list, info, hz, echo; see --help)", 2);
  if (!a) return complain("topic " + verb, a.error().message, 2);
  if (a->help) {
    std::fputs(kTopicHelp, stdout);
    return 0;
  }
  if (verb == "list") return list(*a);
  if (verb == "info") return info(*a);
  if (verb == "echo") return echo(*a);
  return hz(*a);
}

}  // namespace studio::ctl
