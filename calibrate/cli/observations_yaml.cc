#include "observations_yaml.h"

#include <cmath>

#include "calibrate/text.h"
#include "yaml_io/node.h"
#include "yaml_io/rig_yaml.h"

namespace studio::calibrate {
namespace {

constexpr size_t kMaxObservations = 5'000'000;  // e.g. 50 cameras x 1000 frames x 100 points

Expected<int> as_int(const yaml::Node& n) {
  auto v = n.as_int();
  if (!v) return std::unexpected(v.error());
  if (*v < -1000000000 || *v > 1000000000) return n.fail("integer out of range");
  return static_cast<int>(*v);
}

Expected<TargetSpec> target_from(const yaml::Node& node) {
  auto m = yaml::MapReader::from(node);
  if (!m) return std::unexpected(m.error());
  std::string type = "grid";
  if (auto t = m->optional("type")) {
    auto s = t->as_string();
    if (!s) return std::unexpected(s.error());
    type = *s;
  }
  auto rows = m->required("rows");
  if (!rows) return std::unexpected(rows.error());
  auto cols = m->required("cols");
  if (!cols) return std::unexpected(cols.error());
  auto spacing = m->required("spacing");
  if (!spacing) return std::unexpected(spacing.error());
  auto r = as_int(*rows);
  if (!r) return std::unexpected(r.error());
  auto c = as_int(*cols);
  if (!c) return std::unexpected(c.error());
  auto s = spacing->as_double();
  if (!s) return std::unexpected(s.error());
  std::string spec = format("{}:{}x{}:{}", type, *c, *r, yaml::format_double(*s));
  if (type == "charuco") {
    auto marker = m->required("marker");
    if (!marker) return std::unexpected(marker.error());
    auto dict = m->required("dictionary");
    if (!dict) return std::unexpected(dict.error());
    auto mk = marker->as_double();
    if (!mk) return std::unexpected(mk.error());
    auto d = dict->as_string();
    if (!d) return std::unexpected(d.error());
    spec += ":" + yaml::format_double(*mk) + ":" + *d;
  }
  if (auto f = m->finish(); !f) return std::unexpected(f.error());
  auto parsed = parse_target_spec(spec);
  if (!parsed) return std::unexpected(node.error(parsed.error().message));
  return parsed;
}

Expected<FrameObservations> frame_from(const yaml::Node& node, Observations* obs,
                                       size_t* point_count) {
  auto m = yaml::MapReader::from(node);
  if (!m) return std::unexpected(m.error());
  FrameObservations frame;
  auto id = m->required("id");
  if (!id) return std::unexpected(id.error());
  auto ids = id->as_string();
  if (!ids) return std::unexpected(ids.error());
  frame.id = *ids;
  if (auto p = m->optional("placement")) {
    auto text = p->as_string();
    if (!text) return std::unexpected(text.error());
    auto placement = parse_placement(*text);
    if (!placement) return p->fail(placement.error().message);
    frame.placement = *placement;
  }
  if (auto h = m->optional("holdout")) {
    auto b = h->as_bool();
    if (!b) return std::unexpected(b.error());
    frame.holdout = *b;
  }
  auto views = m->required("views");
  if (!views) return std::unexpected(views.error());
  auto entries = views->entries();
  if (!entries) return std::unexpected(entries.error());
  for (const auto& [camera, list] : *entries) {
    View view{camera, {}};
    auto points = list.elements();
    if (!points) return std::unexpected(points.error());
    for (const yaml::Node& p : *points) {
      // YAML aliases let a small file repeat one long list many times; cap what is read.
      if (++*point_count > kMaxObservations)
        return p.fail(format("more than {} observations in one file", kMaxObservations));
      auto v = p.as_doubles(3);
      if (!v) return std::unexpected(v.error());
      const double pid = (*v)[0];
      if (pid != std::floor(pid) || pid < 0 || pid > 1e6)
        return p.fail("the point id must be a non-negative integer");
      view.points.push_back({static_cast<int>(pid), Eigen::Vector2d((*v)[1], (*v)[2])});
    }
    if (obs->camera_index(camera) < 0) obs->cameras.push_back({camera, 0, 0});
    frame.views.push_back(std::move(view));
  }
  if (auto f = m->finish(); !f) return std::unexpected(f.error());
  return frame;
}

}  // namespace

Expected<TargetSpec> read_target_yaml(const std::string& path) {
  auto root = yaml::load_file(path);
  if (!root) return std::unexpected(root.error());
  if (root->is_map()) {
    auto m = yaml::MapReader::from(*root);
    if (m && m->has("target")) return target_from(*m->required("target"));
  }
  return target_from(*root);
}

namespace {

Expected<ObservationsFile> observations_from(const Expected<yaml::Node>& root) {
  if (!root) return std::unexpected(root.error());
  auto m = yaml::MapReader::from(*root);
  if (!m) return std::unexpected(m.error());
  ObservationsFile out;
  if (auto t = m->optional("target")) {
    auto target = target_from(*t);
    if (!target) return std::unexpected(target.error());
    out.target = *target;
  }
  if (auto cams = m->optional("cameras")) {
    auto entries = cams->entries();
    if (!entries) return std::unexpected(entries.error());
    for (const auto& [id, node] : *entries) {
      auto c = yaml::MapReader::from(node);
      if (!c) return std::unexpected(c.error());
      auto w = c->required("width");
      if (!w) return std::unexpected(w.error());
      auto h = c->required("height");
      if (!h) return std::unexpected(h.error());
      auto wi = as_int(*w);
      if (!wi) return std::unexpected(wi.error());
      auto hi = as_int(*h);
      if (!hi) return std::unexpected(hi.error());
      if (*wi <= 0 || *hi <= 0) return node.fail("width and height must be positive");
      if (auto f = c->finish(); !f) return std::unexpected(f.error());
      out.observations.cameras.push_back({id, *wi, *hi});
    }
  }
  auto frames = m->required("frames");
  if (!frames) return std::unexpected(frames.error());
  auto list = frames->elements();
  if (!list) return std::unexpected(list.error());
  if (list->empty()) return frames->fail("expected at least one frame");
  size_t point_count = 0;
  for (const yaml::Node& f : *list) {
    auto frame = frame_from(f, &out.observations, &point_count);
    if (!frame) return std::unexpected(frame.error());
    out.observations.frames.push_back(std::move(*frame));
  }
  if (auto f = m->finish(); !f) return std::unexpected(f.error());
  return out;
}

}  // namespace

Expected<ObservationsFile> read_observations_yaml(const std::string& path) {
  return observations_from(yaml::load_file(path));
}

Expected<ObservationsFile> parse_observations_yaml(std::string_view text, const std::string& name) {
  return observations_from(yaml::parse(text, name));
}

std::string format_observations_yaml(const Observations& obs, const TargetSpec& t) {
  std::string s;
  const char* type = t.kind == TargetSpec::Kind::charuco     ? "charuco"
                     : t.kind == TargetSpec::Kind::chessboard ? "chessboard"
                                                              : "grid";
  s += format("target: {{type: {}, cols: {}, rows: {}, spacing: {}", type, t.cols, t.rows,
              yaml::format_double(t.spacing));
  if (t.kind == TargetSpec::Kind::charuco)
    s += format(", marker: {}, dictionary: DICT_{}", yaml::format_double(t.marker), t.dictionary_name);
  s += "}\ncameras:\n";
  for (const auto& c : obs.cameras)
    if (c.width > 0) s += format("  {}: {{width: {}, height: {}}}\n", yaml::quote(c.id), c.width, c.height);
  if (s.ends_with("cameras:\n")) s.resize(s.size() - 9);
  s += "frames:\n";
  for (const auto& f : obs.frames) {
    s += format("  - id: {}\n    placement: {}\n", yaml::quote(f.id), to_string(f.placement));
    if (f.holdout) s += "    holdout: true\n";
    s += f.views.empty() ? "    views: {}\n" : "    views:\n";  // a frame nobody saw reads back
    for (const auto& v : f.views) {
      s += format("      {}: [", yaml::quote(v.camera_id));
      for (size_t i = 0; i < v.points.size(); ++i)
        s += format("{}[{}, {}, {}]", i ? ", " : "", v.points[i].id,
                    yaml::format_double(v.points[i].pixel.x()),
                    yaml::format_double(v.points[i].pixel.y()));
      s += "]\n";
    }
  }
  return s;
}

}  // namespace studio::calibrate
