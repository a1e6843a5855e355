// Built-in value readers of yaml_io/options.h. Pure Node API: no yaml-cpp here.
#include "yaml_io/options.h"

#include <cmath>
#include <filesystem>
#include <limits>

#include "yaml_io/node.h"

namespace studio::yaml {
namespace {

Expected<void> check_range(const Node& n, double v, const Constraints& c) {
  const bool low = c.min && v < *c.min;
  const bool high = c.max && v > *c.max;
  if (!low && !high) return {};
  if (c.min && c.max) {
    return n.fail("must be in [" + format_double(*c.min) + ", " + format_double(*c.max) +
                  "], got " + format_double(v));
  }
  if (low) return n.fail("must be at least " + format_double(*c.min) + ", got " + format_double(v));
  return n.fail("must be at most " + format_double(*c.max) + ", got " + format_double(v));
}

template <class Int>
Expected<void> read_integer(const Node& n, Int& out, const Constraints& c) {
  Expected<std::int64_t> v = n.as_int();
  if (!v) return std::unexpected(v.error());
  if constexpr (std::is_unsigned_v<Int>) {
    if (*v < 0) return n.fail("must not be negative, got " + std::to_string(*v));
  }
  if (static_cast<long double>(*v) < static_cast<long double>(std::numeric_limits<Int>::min()) ||
      static_cast<long double>(*v) > static_cast<long double>(std::numeric_limits<Int>::max())) {
    return n.fail("integer out of range: " + std::to_string(*v));
  }
  if (Expected<void> ok = check_range(n, static_cast<double>(*v), c); !ok) return ok;
  out = static_cast<Int>(*v);
  return {};
}

Expected<void> check_size(const Node& n, const char* what, const Constraints& c) {
  if (!n.is_sequence()) return n.fail(std::string("expected a sequence of ") + what);
  if (c.size && n.size() != *c.size) {
    return n.fail("expected " + std::to_string(*c.size) + " " + what + ", got " +
                  std::to_string(n.size()));
  }
  return {};
}

}  // namespace

std::string resolve_path(const Node& node, const std::string& path) {
  const std::filesystem::path p(path);
  if (path.empty() || !p.is_relative()) return path;
  return (std::filesystem::path(node.file()).parent_path() / p).lexically_normal().string();
}

Expected<void> read_value(const Node& n, bool& out, const Constraints&) {
  Expected<bool> v = n.as_bool();
  if (!v) return std::unexpected(v.error());
  out = *v;
  return {};
}

Expected<void> read_value(const Node& n, int& out, const Constraints& c) {
  return read_integer(n, out, c);
}
Expected<void> read_value(const Node& n, unsigned& out, const Constraints& c) {
  return read_integer(n, out, c);
}
Expected<void> read_value(const Node& n, std::int64_t& out, const Constraints& c) {
  return read_integer(n, out, c);
}

Expected<void> read_value(const Node& n, std::uint64_t& out, const Constraints& c) {
  std::int64_t v = 0;
  if (Expected<void> ok = read_integer(n, v, c); !ok) return ok;
  if (v < 0) return n.fail("must not be negative, got " + std::to_string(v));
  out = static_cast<std::uint64_t>(v);
  return {};
}

Expected<void> read_value(const Node& n, double& out, const Constraints& c) {
  Expected<double> v = n.as_double();
  if (!v) return std::unexpected(v.error());
  if (Expected<void> ok = check_range(n, *v, c); !ok) return ok;
  out = *v;
  return {};
}

Expected<void> read_value(const Node& n, float& out, const Constraints& c) {
  double v = 0;
  if (Expected<void> ok = read_value(n, v, c); !ok) return ok;
  if (std::abs(v) > std::numeric_limits<float>::max())
    return n.fail("number out of range for float");
  out = static_cast<float>(v);
  return {};
}

Expected<void> read_value(const Node& n, std::string& out, const Constraints& c) {
  Expected<std::string> v = n.as_string();
  if (!v) return std::unexpected(v.error());
  if (!c.choices.empty()) {
    std::string list;
    bool found = false;
    for (const std::string& choice : c.choices) {
      found = found || choice == *v;
      list += (list.empty() ? "" : ", ") + choice;
    }
    if (!found) return n.fail("expected one of " + list + ", got '" + *v + "'");
  }
  out = c.relative_path ? resolve_path(n, *v) : std::move(*v);
  return {};
}

Expected<void> read_value(const Node& n, std::vector<double>& out, const Constraints& c) {
  if (Expected<void> ok = check_size(n, "numbers", c); !ok) return ok;
  Expected<std::vector<Node>> items = n.elements();
  if (!items) return std::unexpected(items.error());
  std::vector<double> values;
  for (const Node& item : *items) {
    double v = 0;
    if (Expected<void> ok = read_value(item, v, c); !ok) return ok;
    values.push_back(v);
  }
  out = std::move(values);
  return {};
}

Expected<void> read_value(const Node& n, std::vector<int>& out, const Constraints& c) {
  if (Expected<void> ok = check_size(n, "integers", c); !ok) return ok;
  Expected<std::vector<Node>> items = n.elements();
  if (!items) return std::unexpected(items.error());
  std::vector<int> values;
  for (const Node& item : *items) {
    int v = 0;
    if (Expected<void> ok = read_integer(item, v, c); !ok) return ok;
    values.push_back(v);
  }
  out = std::move(values);
  return {};
}

Expected<void> read_value(const Node& n, std::vector<std::string>& out, const Constraints& c) {
  if (Expected<void> ok = check_size(n, "strings", c); !ok) return ok;
  Expected<std::vector<Node>> items = n.elements();
  if (!items) return std::unexpected(items.error());
  std::vector<std::string> values;
  Constraints element = c;
  element.size.reset();
  for (const Node& item : *items) {
    std::string v;
    if (Expected<void> ok = read_value(item, v, element); !ok) return ok;
    values.push_back(std::move(v));
  }
  out = std::move(values);
  return {};
}

}  // namespace studio::yaml
