#pragma once
// Strict YAML reading for rig files and every service's configuration (the YAML adapter of
// DESIGN §2 rule 1: yaml-cpp is used only behind this interface and in node/ folders; this header
// does not include it, so users do not inherit it).
//
// Every error is one line naming the file, the line (1-based) and the field path:
//   rig.yaml:14: cameras[1].K: expected 9 numbers, got 8
//   rig.yaml:20: cameras[0].foo: unknown key
//   rig.yaml:3: cameras[0].width: missing required key
// Nothing throws out of this library: yaml-cpp exceptions are caught and turned into Errors.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"

namespace studio::yaml {

// A read-only view of one node of a parsed document, carrying its file name and field path.
// Cheap to copy (shares the document).
class Node {
 public:
  enum class Kind { null, scalar, sequence, map };

  Kind kind() const;
  bool is_null() const { return kind() == Kind::null; }
  bool is_scalar() const { return kind() == Kind::scalar; }
  bool is_sequence() const { return kind() == Kind::sequence; }
  bool is_map() const { return kind() == Kind::map; }

  const std::string& file() const;
  const std::string& path() const;  // "cameras[1].K"; "" for the document root
  int line() const;                 // 1-based

  // "file:line: path: message" (the path part is left out at the root).
  Error error(std::string_view message) const;
  std::unexpected<Error> fail(std::string_view message) const {
    return std::unexpected(error(message));
  }

  // Scalars. Numbers are parsed strictly (whole scalar, C locale); non-finite numbers (.inf,
  // .nan) are errors. Integers reject fractions and out-of-range values. Booleans: true/false.
  Expected<double> as_double() const;
  Expected<std::int64_t> as_int() const;
  Expected<bool> as_bool() const;
  Expected<std::string> as_string() const;  // any scalar, verbatim

  // Sequences. size() is 0 for non-sequences.
  std::size_t size() const;
  Expected<std::vector<Node>> elements() const;  // error unless a sequence
  // A flat sequence of numbers; `count` (when given) is the exact length required:
  // "expected 9 numbers, got 8".
  Expected<std::vector<double>> as_doubles(std::optional<std::size_t> count = std::nullopt) const;

  // Mappings: entries in file order (keys must be scalars; duplicate keys are an error).
  Expected<std::vector<std::pair<std::string, Node>>> entries() const;

  struct Impl;  // holds the yaml-cpp node; defined in node.cc
  explicit Node(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

 private:
  std::shared_ptr<const Impl> impl_;
};

// Parses a file / a string (`name` is used in messages). Errors: missing or unreadable file,
// YAML syntax errors (with their line), an empty document.
Expected<Node> load_file(const std::string& path);
Expected<Node> parse(std::string_view text, const std::string& name);

// Strict reading of one mapping: every key must be consumed (required() or optional()) before
// finish(), which reports the first key that was not: "file:line: path.key: unknown key".
class MapReader {
 public:
  // Error unless `node` is a mapping: "file:line: path: expected a mapping".
  static Expected<MapReader> from(const Node& node);

  const Node& node() const { return node_; }
  bool has(std::string_view key) const;
  // Missing key: "file:line(of the mapping): path.key: missing required key".
  Expected<Node> required(std::string_view key);
  std::optional<Node> optional(std::string_view key);
  // Error if more than one of `keys` is present, or (required) none is:
  // "file:line: path: expected exactly one of K, cahv, P".
  Expected<std::optional<std::string>> one_of(std::vector<std::string_view> keys, bool required);
  Expected<void> finish() const;

 private:
  explicit MapReader(Node node, std::vector<std::pair<std::string, Node>> entries)
      : node_(std::move(node)), entries_(std::move(entries)), used_(entries_.size(), false) {}
  Node node_;
  std::vector<std::pair<std::string, Node>> entries_;
  std::vector<bool> used_;
};

// Shortest text that reads back to exactly the same double ("0.1", "1e-07", "704").
std::string format_double(double value);

}  // namespace studio::yaml
