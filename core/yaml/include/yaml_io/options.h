#pragma once
// Declarative, strict reading of a service's Options struct from YAML.
//
//   struct Options {
//     std::string rig;  int grid = 64;  double margin = 0.02;  Axis axis = Axis::y;
//     Expected<void> validate() const;
//   };
//   const yaml::Schema<Options> schema{
//       yaml::field("rig", &Options::rig).required().relative_path(),
//       yaml::field("grid", &Options::grid).range(8, 1024),
//       yaml::field("margin", &Options::margin).min(0),
//       yaml::enum_field("axis", &Options::axis, {{"x", Axis::x}, {"y", Axis::y}, {"z", Axis::z}}),
//   };
//   Expected<Options> options = schema.read_file("hull.yaml");
//
// Optional fields keep the struct's default member value. Unknown keys, missing required keys,
// wrong types, out-of-range numbers and choices not in the list are errors naming file, line and
// field ("hull.yaml:4: grid: must be in [8, 1024], got 4"). When Options has
// `Expected<void> validate() const`, it runs last and its message is prefixed with the file name
// and line of the mapping. Nested structs take their own Schema; anything else takes a parser.

#include <concepts>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "yaml_io/node.h"

namespace studio::yaml {

// Checks applied by the built-in readers (numbers: min/max, per element for number lists;
// strings: choices; lists: exact size; strings: relative_path resolves against the folder of the
// YAML file, leaving absolute paths alone).
struct Constraints {
  std::optional<double> min, max;
  std::vector<std::string> choices;
  std::optional<std::size_t> size;
  bool relative_path = false;
};

// A path as written in the YAML file of `node`: relative ones resolve against that file's folder,
// absolute (and empty) ones are left alone. The built-in readers apply it for relative_path().
std::string resolve_path(const Node& node, const std::string& path);

// Built-in readers (node.cc / options.cc), one per supported member type.
Expected<void> read_value(const Node& node, bool& out, const Constraints& c);
Expected<void> read_value(const Node& node, int& out, const Constraints& c);
Expected<void> read_value(const Node& node, unsigned& out, const Constraints& c);
Expected<void> read_value(const Node& node, std::int64_t& out, const Constraints& c);
Expected<void> read_value(const Node& node, std::uint64_t& out, const Constraints& c);
Expected<void> read_value(const Node& node, double& out, const Constraints& c);
Expected<void> read_value(const Node& node, float& out, const Constraints& c);
Expected<void> read_value(const Node& node, std::string& out, const Constraints& c);
Expected<void> read_value(const Node& node, std::vector<double>& out, const Constraints& c);
Expected<void> read_value(const Node& node, std::vector<int>& out, const Constraints& c);
Expected<void> read_value(const Node& node, std::vector<std::string>& out, const Constraints& c);

template <class T>
class Schema;

template <class T>
class Field {
 public:
  using Reader = std::function<Expected<void>(const Node&, T&, const Constraints&)>;
  Field(std::string name, Reader reader) : name_(std::move(name)), reader_(std::move(reader)) {}

  Field& required() {
    required_ = true;
    return *this;
  }
  Field& range(double lo, double hi) {
    constraints_.min = lo;
    constraints_.max = hi;
    return *this;
  }
  Field& min(double lo) {
    constraints_.min = lo;
    return *this;
  }
  Field& max(double hi) {
    constraints_.max = hi;
    return *this;
  }
  Field& one_of(std::vector<std::string> choices) {
    constraints_.choices = std::move(choices);
    return *this;
  }
  Field& size(std::size_t n) {
    constraints_.size = n;
    return *this;
  }
  Field& relative_path() {
    constraints_.relative_path = true;
    return *this;
  }

  const std::string& name() const { return name_; }
  bool is_required() const { return required_; }
  Expected<void> read(const Node& node, T& target) const {
    return reader_(node, target, constraints_);
  }

 private:
  std::string name_;
  Reader reader_;
  bool required_ = false;
  Constraints constraints_;
};

// A member of a built-in type.
template <class T, class M>
Field<T> field(std::string name, M T::*member) {
  return Field<T>(std::move(name), [member](const Node& n, T& t, const Constraints& c) {
    return read_value(n, t.*member, c);
  });
}

// A member read by a custom parser: Expected<M> parse(const Node&).
template <class T, class M, class Parse>
requires std::invocable<const Parse&, const Node&> Field<T> field(std::string name, M T::*member,
                                                                  Parse parse) {
  return Field<T>(std::move(name),
                  [member, parse = std::move(parse)](const Node& n, T& t,
                                                     const Constraints&) -> Expected<void> {
                    Expected<M> v = parse(n);
                    if (!v) return std::unexpected(v.error());
                    t.*member = std::move(*v);
                    return {};
                  });
}

// A nested struct with its own schema (a sub-mapping).
template <class T, class M>
Field<T> field(std::string name, M T::*member, Schema<M> nested) {
  return Field<T>(std::move(name),
                  [member, nested = std::move(nested)](const Node& n, T& t,
                                                       const Constraints&) -> Expected<void> {
                    Expected<M> v = nested.read(n, t.*member);
                    if (!v) return std::unexpected(v.error());
                    t.*member = std::move(*v);
                    return {};
                  });
}

// An enum member spelled by names: "expected one of x, y, z, got 'w'".
template <class T, class E>
Field<T> enum_field(std::string name, E T::*member, std::vector<std::pair<std::string, E>> names) {
  return Field<T>(std::move(name),
                  [member, names = std::move(names)](const Node& n, T& t,
                                                     const Constraints&) -> Expected<void> {
                    Expected<std::string> s = n.as_string();
                    if (!s) return std::unexpected(s.error());
                    std::string list;
                    for (const auto& [text, value] : names) {
                      if (text == *s) {
                        t.*member = value;
                        return {};
                      }
                      list += (list.empty() ? "" : ", ") + text;
                    }
                    return n.fail("expected one of " + list + ", got '" + *s + "'");
                  });
}

template <class T>
class Schema {
 public:
  Schema(std::initializer_list<Field<T>> fields) : fields_(fields) {}

  bool has_field(std::string_view name) const {
    for (const Field<T>& f : fields_)
      if (f.name() == name) return true;
    return false;
  }

  // Reads a mapping on top of `defaults`.
  Expected<T> read(const Node& node, T defaults = T{}) const {
    Expected<MapReader> map = MapReader::from(node);
    if (!map) return std::unexpected(map.error());
    return read_fields(*map, std::move(defaults), true);
  }

  // Reads this schema's keys out of `map`, a mapping that holds other keys too (a service
  // config, whose common keys runtime::service_main reads): the keys are consumed and the caller
  // finishes the map (`finish` = true finishes it here). validate() runs as in read().
  Expected<T> read_fields(MapReader& map, T defaults = T{}, bool finish = false) const {
    T out = std::move(defaults);
    for (const Field<T>& f : fields_) {
      std::optional<Node> value;
      if (f.is_required()) {
        Expected<Node> v = map.required(f.name());
        if (!v) return std::unexpected(v.error());
        value = *v;
      } else {
        value = map.optional(f.name());
      }
      if (value) {
        if (Expected<void> ok = f.read(*value, out); !ok) return std::unexpected(ok.error());
      }
    }
    if (finish) {
      if (Expected<void> ok = map.finish(); !ok) return std::unexpected(ok.error());
    }
    if constexpr (requires(const T& t) {
                    { t.validate() } -> std::same_as<Expected<void>>;
                  }) {
      if (Expected<void> ok = out.validate(); !ok) return map.node().fail(ok.error().message);
    }
    return out;
  }

  Expected<T> read_file(const std::string& path, T defaults = T{}) const {
    Expected<Node> root = load_file(path);
    if (!root) return std::unexpected(root.error());
    return read(*root, std::move(defaults));
  }

 private:
  std::vector<Field<T>> fields_;
};

}  // namespace studio::yaml
