// rig.yaml reader and writer (yaml_io/rig_yaml.h). Reads through the strict Node API.
#include "yaml_io/rig_yaml.h"

#include <Eigen/Core>
#include <fstream>
#include <set>
#include <sstream>

namespace studio::yaml {
namespace {

template <int Rows, int Cols>
Expected<Eigen::Matrix<double, Rows, Cols>> read_matrix(const Node& n) {
  Expected<std::vector<double>> v = n.as_doubles(Rows * Cols);
  if (!v) return std::unexpected(v.error());
  Eigen::Matrix<double, Rows, Cols> m;
  for (int i = 0; i < Rows * Cols; ++i) m(i / Cols, i % Cols) = (*v)[i];
  return m;
}

Expected<Eigen::Vector3d> read_vector3(const Node& n) {
  Expected<Eigen::Matrix<double, 3, 1>> v = read_matrix<3, 1>(n);
  if (!v) return std::unexpected(v.error());
  return Eigen::Vector3d(*v);
}

Expected<int> read_size(MapReader& map, std::string_view key) {
  Expected<Node> n = map.required(key);
  if (!n) return std::unexpected(n.error());
  Expected<std::int64_t> v = n->as_int();
  if (!v) return std::unexpected(v.error());
  if (*v <= 0 || *v > 1'000'000)
    return n->fail("must be a positive pixel count, got " + std::to_string(*v));
  return static_cast<int>(*v);
}

Expected<Cahv> read_cahv(const Node& n) {
  Expected<MapReader> map = MapReader::from(n);
  if (!map) return std::unexpected(map.error());
  Cahv cahv;
  for (auto [key, target] : {std::pair<const char*, Eigen::Vector3d*>{"C", &cahv.C},
                             {"A", &cahv.A},
                             {"H", &cahv.H},
                             {"V", &cahv.V}}) {
    Expected<Node> v = map->required(key);
    if (!v) return std::unexpected(v.error());
    Expected<Eigen::Vector3d> x = read_vector3(*v);
    if (!x) return std::unexpected(x.error());
    *target = *x;
  }
  if (Expected<void> ok = map->finish(); !ok) return std::unexpected(ok.error());
  return cahv;
}

Expected<Rigid3> read_pose(const Node& n) {
  Expected<MapReader> map = MapReader::from(n);
  if (!map) return std::unexpected(map.error());
  Expected<Node> r = map->required("R");
  if (!r) return std::unexpected(r.error());
  Expected<Node> t = map->required("t");
  if (!t) return std::unexpected(t.error());
  if (Expected<void> ok = map->finish(); !ok) return std::unexpected(ok.error());
  Expected<Eigen::Matrix3d> R = read_matrix<3, 3>(*r);
  if (!R) return std::unexpected(R.error());
  Expected<Eigen::Vector3d> tv = read_vector3(*t);
  if (!tv) return std::unexpected(tv.error());
  Expected<Rigid3> pose = rigid_from_matrix(*R, *tv);
  if (!pose) return r->fail(pose.error().message);
  return pose;
}

// The camera keys of one mapping; the caller finishes the map (projectors add "screen").
Expected<Camera> read_camera_fields(MapReader& map) {
  Camera camera;
  Expected<Node> id = map.required("id");
  if (!id) return std::unexpected(id.error());
  Expected<std::string> id_text = id->as_string();
  if (!id_text) return std::unexpected(id_text.error());
  if (id_text->empty()) return id->fail("empty id");
  camera.id = *id_text;
  Expected<int> width = read_size(map, "width");
  if (!width) return std::unexpected(width.error());
  Expected<int> height = read_size(map, "height");
  if (!height) return std::unexpected(height.error());
  camera.width = *width;
  camera.height = *height;

  Expected<std::optional<std::string>> model = map.one_of({"K", "cahv", "P"}, true);
  if (!model) return std::unexpected(model.error());
  const Node model_node = *map.optional(**model);
  if (**model == "K") {
    Expected<Eigen::Matrix3d> K = read_matrix<3, 3>(model_node);
    if (!K) return std::unexpected(K.error());
    Expected<Intrinsics> k = intrinsics_from_matrix(*K);
    if (!k) return model_node.fail(k.error().message);
    camera.intrinsics = *k;
    Expected<Node> pose_node = map.required("cam_from_world");
    if (!pose_node) return std::unexpected(pose_node.error());
    Expected<Rigid3> pose = read_pose(*pose_node);
    if (!pose) return std::unexpected(pose.error());
    camera.cam_from_world = *pose;
  } else {
    if (std::optional<Node> extra = map.optional("cam_from_world")) {
      return extra->fail("not allowed with " + **model + " (it already holds the pose)");
    }
    Expected<Camera> from_model;
    if (**model == "cahv") {
      Expected<Cahv> cahv = read_cahv(model_node);
      if (!cahv) return std::unexpected(cahv.error());
      from_model = camera_from_cahv(*cahv, camera.width, camera.height);
    } else {
      Expected<Eigen::Matrix<double, 3, 4>> P = read_matrix<3, 4>(model_node);
      if (!P) return std::unexpected(P.error());
      from_model = camera_from_projection_matrix(*P, camera.width, camera.height);
    }
    if (!from_model) return model_node.fail(from_model.error().message);
    camera.intrinsics = from_model->intrinsics;
    camera.cam_from_world = from_model->cam_from_world;
  }

  Expected<std::optional<std::string>> distortion = map.one_of({"radial", "opencv"}, false);
  if (!distortion) return std::unexpected(distortion.error());
  if (*distortion) {
    const Node n = *map.optional(**distortion);
    const bool radial = **distortion == "radial";
    Expected<std::vector<double>> c = n.as_doubles(radial ? 2 : 5);
    if (!c) return std::unexpected(c.error());
    const std::vector<double>& v = *c;
    camera.distortion =
        radial ? Distortion::radial(v[0], v[1]) : Distortion::opencv(v[0], v[1], v[2], v[3], v[4]);
  }
  return camera;
}

Expected<std::array<Eigen::Vector3d, 4>> read_screen(const Node& n) {
  Expected<MapReader> map = MapReader::from(n);
  if (!map) return std::unexpected(map.error());
  Expected<Node> corners = map->required("corners");
  if (!corners) return std::unexpected(corners.error());
  if (Expected<void> ok = map->finish(); !ok) return std::unexpected(ok.error());
  if (!corners->is_sequence() || corners->size() != 4) {
    return corners->fail(
        "expected 4 corners [x, y, z] (lower-left, lower-right, upper-right, "
        "upper-left), got " +
        (corners->is_sequence() ? std::to_string(corners->size()) : std::string("no sequence")));
  }
  std::array<Eigen::Vector3d, 4> out;
  Expected<std::vector<Node>> items = corners->elements();
  if (!items) return std::unexpected(items.error());
  for (int i = 0; i < 4; ++i) {
    Expected<Eigen::Vector3d> c = read_vector3((*items)[i]);
    if (!c) return std::unexpected(c.error());
    out[i] = *c;
  }
  return out;
}

template <class Item, class ReadItem>
Expected<std::vector<Item>> read_list(MapReader& root, std::string_view key, ReadItem read_item) {
  std::vector<Item> out;
  std::optional<Node> list = root.optional(key);
  if (!list || list->is_null()) return out;
  Expected<std::vector<Node>> items = list->elements();
  if (!items) return std::unexpected(items.error());
  for (const Node& item : *items) {
    Expected<MapReader> map = MapReader::from(item);
    if (!map) return std::unexpected(map.error());
    Expected<Item> value = read_item(*map);
    if (!value) return std::unexpected(value.error());
    if (Expected<void> ok = map->finish(); !ok) return std::unexpected(ok.error());
    out.push_back(std::move(*value));
  }
  return out;
}

void append_numbers(std::ostringstream& out, const double* values, int n) {
  out << '[';
  for (int i = 0; i < n; ++i) out << (i ? ", " : "") << format_double(values[i]);
  out << ']';
}

}  // namespace

Expected<Camera> read_camera(const Node& node) {
  Expected<MapReader> map = MapReader::from(node);
  if (!map) return std::unexpected(map.error());
  Expected<Camera> camera = read_camera_fields(*map);
  if (!camera) return camera;
  if (Expected<void> ok = map->finish(); !ok) return std::unexpected(ok.error());
  return camera;
}

Expected<Rig> read_rig(const Node& root) {
  Expected<MapReader> map = MapReader::from(root);
  if (!map) return std::unexpected(map.error());
  if (std::optional<Node> units = map->optional("units")) {
    Expected<std::string> u = units->as_string();
    if (!u) return std::unexpected(u.error());
    if (*u != "metres" && *u != "meters")
      return units->fail("only metres are supported, got '" + *u + "'");
  }
  Rig rig;
  Expected<std::vector<Camera>> cameras = read_list<Camera>(*map, "cameras", read_camera_fields);
  if (!cameras) return std::unexpected(cameras.error());
  rig.cameras = std::move(*cameras);
  Expected<std::vector<Projector>> projectors =
      read_list<Projector>(*map, "projectors", [](MapReader& m) -> Expected<Projector> {
        Projector p;
        Expected<Camera> camera = read_camera_fields(m);
        if (!camera) return std::unexpected(camera.error());
        p.camera = std::move(*camera);
        Expected<Node> screen = m.required("screen");
        if (!screen) return std::unexpected(screen.error());
        Expected<std::array<Eigen::Vector3d, 4>> corners = read_screen(*screen);
        if (!corners) return std::unexpected(corners.error());
        p.screen = *corners;
        return p;
      });
  if (!projectors) return std::unexpected(projectors.error());
  rig.projectors = std::move(*projectors);
  if (Expected<void> ok = map->finish(); !ok) return std::unexpected(ok.error());
  if (Expected<void> ok = rig.validate(); !ok) return root.fail(ok.error().message);
  return rig;
}

Expected<Rig> parse_rig(std::string_view text, const std::string& name) {
  Expected<Node> root = parse(text, name);
  if (!root) return std::unexpected(root.error());
  return read_rig(*root);
}

Expected<Rig> read_rig(const std::string& path) {
  Expected<Node> root = load_file(path);
  if (!root) return std::unexpected(root.error());
  return read_rig(*root);
}

std::string quote(std::string_view text) {
  static const std::set<std::string, std::less<>> special = {
      "~",   "null", "Null", "NULL", "true", "True", "TRUE", "false", "False", "FALSE", "yes",
      "Yes", "YES",  "no",   "No",   "NO",   "on",   "On",   "ON",    "off",   "Off",   "OFF"};
  bool plain = !text.empty() && !special.contains(text);
  for (std::size_t i = 0; plain && i < text.size(); ++i) {
    const char c = text[i];
    const bool word =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    plain = word || (i > 0 && (c == '-' || c == '.' || c == '/'));
  }
  if (plain) return std::string(text);
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned char>(c));
      out += hex;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string format_camera(const Camera& c, int indent) {
  const std::string pad(indent, ' ');
  std::ostringstream out;
  out << pad << "id: " << quote(c.id) << '\n';
  out << pad << "width: " << c.width << '\n';
  out << pad << "height: " << c.height << '\n';
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> K = c.intrinsics.K();
  out << pad << "K: ";
  append_numbers(out, K.data(), 9);
  out << '\n';
  const Distortion& d = c.distortion;
  if (d.model == Distortion::Model::radial) {
    const double v[] = {d.rd3, d.rd5};
    out << pad << "radial: ";
    append_numbers(out, v, 2);
    out << '\n';
  } else if (d.model == Distortion::Model::opencv) {
    const double v[] = {d.k1, d.k2, d.p1, d.p2, d.k3};
    out << pad << "opencv: ";
    append_numbers(out, v, 5);
    out << '\n';
  }
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = c.cam_from_world.R();
  out << pad << "cam_from_world: {R: ";
  append_numbers(out, R.data(), 9);
  out << ", t: ";
  append_numbers(out, c.cam_from_world.translation.data(), 3);
  out << "}\n";
  return out.str();
}

std::string format_rig(const Rig& rig) {
  std::ostringstream out;
  out << "units: metres\n";
  out << "cameras:" << (rig.cameras.empty() ? " []\n" : "\n");
  for (const Camera& c : rig.cameras) {
    std::string body = format_camera(c, 4);
    body.replace(0, 4, "  - ");
    out << body;
  }
  out << "projectors:" << (rig.projectors.empty() ? " []\n" : "\n");
  for (const Projector& p : rig.projectors) {
    std::string body = format_camera(p.camera, 4);
    body.replace(0, 4, "  - ");
    out << body << "    screen: {corners: [";
    for (int i = 0; i < 4; ++i) {
      out << (i ? ", " : "");
      append_numbers(out, p.screen[i].data(), 3);
    }
    out << "]}\n";
  }
  return out.str();
}

Expected<void> write_rig(const Rig& rig, const std::string& path) {
  if (Expected<void> ok = rig.validate(); !ok)
    return fail(path + ": not written: " + ok.error().message);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return fail(path + ": cannot open for writing");
  out << format_rig(rig);
  out.close();
  if (!out) return fail(path + ": write error");
  return {};
}

}  // namespace studio::yaml
