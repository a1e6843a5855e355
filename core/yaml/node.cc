// yaml_io/node.h over yaml-cpp. Every yaml-cpp call that can throw is wrapped here.
#include "yaml_io/node.h"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

namespace studio::yaml {

struct Node::Impl {
  std::shared_ptr<const std::string> file;
  std::string path;
  YAML::Node node;
  int line = 0;  // 1-based; inherited from the parent when yaml-cpp has no mark (null nodes)
};

namespace {

int line_of(const YAML::Node& node, int fallback) {
  try {
    const YAML::Mark mark = node.Mark();
    return mark.is_null() ? fallback : mark.line + 1;
  } catch (const YAML::Exception&) {
    return fallback;
  }
}

// `line`: the line to report for this node (a mapping value reports the line of its key).
Node make(std::shared_ptr<const std::string> file, std::string path, YAML::Node node, int line) {
  auto impl = std::make_shared<Node::Impl>();
  impl->file = std::move(file);
  impl->path = std::move(path);
  impl->line = line;
  impl->node = std::move(node);
  return Node(std::move(impl));
}

std::string child_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

// Messages are one line of reasonable length whatever the file holds: control characters become
// '?', and very long messages (huge scalars quoted back) are shortened in the middle.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (text.size() > 400) text = text.substr(0, 300) + "..." + text.substr(text.size() - 80);
  return text;
}

std::string plural(std::size_t n, const char* word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

}  // namespace

Node::Kind Node::kind() const {
  switch (impl_->node.Type()) {
    case YAML::NodeType::Scalar:
      return Kind::scalar;
    case YAML::NodeType::Sequence:
      return Kind::sequence;
    case YAML::NodeType::Map:
      return Kind::map;
    default:
      return Kind::null;
  }
}

const std::string& Node::file() const { return *impl_->file; }
const std::string& Node::path() const { return impl_->path; }
int Node::line() const { return impl_->line; }

Error Node::error(std::string_view message) const {
  std::string text = file() + ":" + std::to_string(line()) + ": ";
  if (!path().empty()) text += path() + ": ";
  text += message;
  return Error{one_line(std::move(text))};
}

Expected<std::string> Node::as_string() const {
  if (!is_scalar()) return fail("expected a scalar");
  return impl_->node.Scalar();
}

Expected<double> Node::as_double() const {
  if (!is_scalar()) return fail("expected a number");
  const std::string& s = impl_->node.Scalar();
  const char* begin = s.data();
  const char* end = begin + s.size();
  if (begin != end && *begin == '+') ++begin;
  double value = 0;
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  const bool yaml_special = s == ".inf" || s == "-.inf" || s == "+.inf" || s == ".Inf" ||
                            s == "-.Inf" || s == ".INF" || s == "-.INF" || s == ".nan" ||
                            s == ".NaN" || s == ".NAN";
  if (yaml_special || (ec == std::errc() && ptr == end && !std::isfinite(value))) {
    return fail("non-finite number '" + s + "'");
  }
  if (ec == std::errc::result_out_of_range) return fail("number out of range '" + s + "'");
  if (ec != std::errc() || ptr != end || begin == end) {
    return fail("expected a number, got '" + s + "'");
  }
  return value;
}

Expected<std::int64_t> Node::as_int() const {
  if (!is_scalar()) return fail("expected an integer");
  const std::string& s = impl_->node.Scalar();
  const char* begin = s.data();
  const char* end = begin + s.size();
  if (begin != end && *begin == '+') ++begin;
  std::int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec == std::errc::result_out_of_range) return fail("integer out of range '" + s + "'");
  if (ec != std::errc() || ptr != end || begin == end) {
    return fail("expected an integer, got '" + s + "'");
  }
  return value;
}

Expected<bool> Node::as_bool() const {
  if (!is_scalar()) return fail("expected true or false");
  const std::string& s = impl_->node.Scalar();
  if (s == "true" || s == "True" || s == "TRUE") return true;
  if (s == "false" || s == "False" || s == "FALSE") return false;
  return fail("expected true or false, got '" + s + "'");
}

std::size_t Node::size() const { return is_sequence() ? impl_->node.size() : 0; }

Expected<std::vector<Node>> Node::elements() const {
  if (!is_sequence()) return fail("expected a sequence");
  std::vector<Node> out;
  try {
    std::size_t i = 0;
    for (const YAML::Node& child : impl_->node) {
      out.push_back(make(impl_->file, impl_->path + "[" + std::to_string(i) + "]", child,
                         line_of(child, line())));
      ++i;
    }
  } catch (const YAML::Exception& e) {
    return fail(e.msg);
  }
  return out;
}

Expected<std::vector<double>> Node::as_doubles(std::optional<std::size_t> count) const {
  const auto expected_what = [&] {
    return count ? "expected " + plural(*count, "number") : std::string("expected numbers");
  };
  if (!is_sequence())
    return fail(expected_what() + ", got " +
                (is_map()    ? "a mapping"
                 : is_null() ? "nothing"
                             : "a scalar"));
  if (count && size() != *count) return fail(expected_what() + ", got " + std::to_string(size()));
  Expected<std::vector<Node>> items = elements();
  if (!items) return std::unexpected(items.error());
  std::vector<double> out;
  out.reserve(items->size());
  for (const Node& item : *items) {
    Expected<double> v = item.as_double();
    if (!v) return std::unexpected(v.error());
    out.push_back(*v);
  }
  return out;
}

Expected<std::vector<std::pair<std::string, Node>>> Node::entries() const {
  if (!is_map()) return fail("expected a mapping");
  std::vector<std::pair<std::string, Node>> out;
  try {
    for (const auto& kv : impl_->node) {
      if (!kv.first.IsScalar()) {
        return std::unexpected(make(impl_->file, impl_->path, kv.first, line_of(kv.first, line()))
                                   .error("mapping keys must be scalars"));
      }
      const std::string key = kv.first.Scalar();
      const int key_line = line_of(kv.first, line());
      for (const auto& [seen, node] : out) {
        if (seen == key) {
          return std::unexpected(make(impl_->file, child_path(impl_->path, key), kv.first, key_line)
                                     .error("duplicate key"));
        }
      }
      out.emplace_back(key, make(impl_->file, child_path(impl_->path, key), kv.second, key_line));
    }
  } catch (const YAML::Exception& e) {
    return fail(e.msg);
  }
  return out;
}

Expected<Node> parse(std::string_view text, const std::string& name) {
  auto file = std::make_shared<const std::string>(name);
  try {
    YAML::Node root = YAML::Load(std::string(text));
    if (!root.IsDefined() || root.IsNull()) return studio::fail(name + ": empty YAML document");
    return make(file, "", root, line_of(root, 1));
  } catch (const YAML::Exception& e) {
    const int line = e.mark.is_null() ? 1 : e.mark.line + 1;
    return studio::fail(one_line(name + ":" + std::to_string(line) + ": not valid YAML: " + e.msg));
  } catch (const std::exception& e) {  // e.g. std::bad_alloc on absurd inputs
    return studio::fail(one_line(name + ": cannot parse YAML: " + e.what()));
  }
}

Expected<Node> load_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return studio::fail(path + ": cannot open file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return studio::fail(path + ": read error");
  return parse(buffer.str(), path);
}

Expected<MapReader> MapReader::from(const Node& node) {
  Expected<std::vector<std::pair<std::string, Node>>> entries = node.entries();
  if (!entries) return std::unexpected(entries.error());
  return MapReader(node, std::move(*entries));
}

bool MapReader::has(std::string_view key) const {
  for (const auto& [k, v] : entries_) {
    if (k == key) return true;
  }
  return false;
}

std::optional<Node> MapReader::optional(std::string_view key) {
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (entries_[i].first == key) {
      used_[i] = true;
      return entries_[i].second;
    }
  }
  return std::nullopt;
}

Expected<Node> MapReader::required(std::string_view key) {
  if (std::optional<Node> n = optional(key)) return *n;
  return std::unexpected(Error{one_line(node_.file() + ":" + std::to_string(node_.line()) + ": " +
                                        child_path(node_.path(), key) + ": missing required key")});
}

Expected<std::optional<std::string>> MapReader::one_of(std::vector<std::string_view> keys,
                                                       bool required) {
  std::optional<std::string> found;
  std::string names;
  for (std::string_view k : keys) {
    names += (names.empty() ? "" : ", ") + std::string(k);
  }
  for (std::string_view k : keys) {
    if (!has(k)) continue;
    if (found)
      return node_.fail("expected exactly one of " + names + ", got both " + *found + " and " +
                        std::string(k));
    found = std::string(k);
  }
  if (!found && required) return node_.fail("expected one of " + names);
  return found;
}

Expected<void> MapReader::finish() const {
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (!used_[i]) {
      const Node& n = entries_[i].second;
      return std::unexpected(Error{
          one_line(n.file() + ":" + std::to_string(n.line()) + ": " + n.path() + ": unknown key")});
    }
  }
  return {};
}

std::string format_double(double value) {
  char buffer[64];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  if (ec != std::errc()) return "nan";
  return std::string(buffer, ptr);
}

}  // namespace studio::yaml
