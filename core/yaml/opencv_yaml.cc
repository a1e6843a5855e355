// OpenCV FileStorage YAML import / export (yaml_io/opencv_yaml.h).
#include "yaml_io/opencv_yaml.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "yaml_io/node.h"

namespace studio::yaml {
namespace {

struct MatrixValue {
  int rows = 0, cols = 0;
  std::vector<double> data;
  Node node;
};

// An !!opencv-matrix mapping (rows, cols, dt, data) or a plain list (a column vector).
Expected<MatrixValue> read_matrix(const Node& n) {
  if (n.is_sequence()) {
    Expected<std::vector<double>> data = n.as_doubles();
    if (!data) return std::unexpected(data.error());
    return MatrixValue{static_cast<int>(data->size()), 1, std::move(*data), n};
  }
  Expected<MapReader> map = MapReader::from(n);
  if (!map) return n.fail("expected an !!opencv-matrix or a list of numbers");
  MatrixValue m{0, 0, {}, n};
  for (auto [key, target] : {std::pair<const char*, int*>{"rows", &m.rows}, {"cols", &m.cols}}) {
    Expected<Node> v = map->required(key);
    if (!v) return std::unexpected(v.error());
    Expected<std::int64_t> i = v->as_int();
    if (!i) return std::unexpected(i.error());
    if (*i < 1 || *i > 64) return v->fail("must be in [1, 64], got " + std::to_string(*i));
    *target = static_cast<int>(*i);
  }
  Expected<Node> dt = map->required("dt");
  if (!dt) return std::unexpected(dt.error());
  Expected<std::string> type = dt->as_string();
  if (!type) return std::unexpected(type.error());
  if (*type != "d" && *type != "f" && *type != "i" && *type != "s" && *type != "u" &&
      *type != "w" && *type != "c") {
    return dt->fail("unsupported element type '" + *type + "' (expected one of d f i s u w c)");
  }
  Expected<Node> data = map->required("data");
  if (!data) return std::unexpected(data.error());
  const std::size_t count = static_cast<std::size_t>(m.rows) * m.cols;
  if (data->is_sequence() && data->size() != count) {
    return data->fail("expected " + std::to_string(count) + " numbers (" + std::to_string(m.rows) +
                      "x" + std::to_string(m.cols) + "), got " + std::to_string(data->size()));
  }
  Expected<std::vector<double>> values = data->as_doubles(count);
  if (!values) return std::unexpected(values.error());
  m.data = std::move(*values);
  return m;
}

// The first key of `names` present in the map, read as a matrix.
Expected<std::optional<MatrixValue>> find_matrix(MapReader& map,
                                                 std::initializer_list<const char*> names) {
  for (const char* name : names) {
    if (std::optional<Node> n = map.optional(name)) {
      Expected<MatrixValue> m = read_matrix(*n);
      if (!m) return std::unexpected(m.error());
      return std::optional<MatrixValue>(std::move(*m));
    }
  }
  return std::optional<MatrixValue>();
}

Expected<Intrinsics> to_intrinsics(const MatrixValue& m) {
  if (m.rows * m.cols != 9 || (m.rows != 3 && m.node.is_map())) {
    return m.node.fail("expected a 3x3 camera matrix, got " + std::to_string(m.rows) + "x" +
                       std::to_string(m.cols));
  }
  Eigen::Matrix3d K;
  for (int i = 0; i < 9; ++i) K(i / 3, i % 3) = m.data[i];
  Expected<Intrinsics> k = intrinsics_from_matrix(K);
  if (!k) return m.node.fail(k.error().message);
  return k;
}

Expected<Distortion> to_distortion(const std::optional<MatrixValue>& m) {
  if (!m) return Distortion::none();
  const std::vector<double>& d = m->data;
  if (m->rows != 1 && m->cols != 1) return m->node.fail("expected a distortion vector");
  if (d.size() != 4 && d.size() != 5 && d.size() != 8 && d.size() != 12 && d.size() != 14) {
    return m->node.fail("expected 4, 5, 8, 12 or 14 distortion coefficients, got " +
                        std::to_string(d.size()));
  }
  for (std::size_t i = 5; i < d.size(); ++i) {
    if (d[i] != 0) {
      return m->node.fail("only k1 k2 p1 p2 k3 are supported; coefficient " + std::to_string(i) +
                          " (rational / thin-prism / tilt) is not zero");
    }
  }
  return Distortion::opencv(d[0], d[1], d[2], d[3], d.size() > 4 ? d[4] : 0.0);
}

Expected<Rigid3> to_pose(const std::optional<MatrixValue>& r, const std::optional<MatrixValue>& t,
                         const Node& root) {
  if (!r && !t) return Rigid3::identity();
  if (!r || !t) return root.fail("R and T must be given together");
  if (t->data.size() != 3 || (t->rows != 1 && t->cols != 1)) {
    return t->node.fail("expected a 3-vector translation, got " + std::to_string(t->rows) + "x" +
                        std::to_string(t->cols));
  }
  const Eigen::Vector3d tv(t->data[0], t->data[1], t->data[2]);
  Eigen::Matrix3d R;
  if (r->data.size() == 3 && (r->rows == 1 || r->cols == 1)) {  // Rodrigues vector
    const Eigen::Vector3d w(r->data[0], r->data[1], r->data[2]);
    const double angle = w.norm();
    R = angle > 0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
  } else if (r->data.size() == 9 && (r->rows == 3 || !r->node.is_map())) {  // 3x3 row-major
    for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = r->data[i];
  } else {
    return r->node.fail("expected a 3x3 rotation matrix or a 3-vector, got " +
                        std::to_string(r->rows) + "x" + std::to_string(r->cols));
  }
  Expected<Rigid3> pose = rigid_from_matrix(R, tv);
  if (!pose) return r->node.fail(pose.error().message);
  return pose;
}

Expected<int> find_size(MapReader& map, std::initializer_list<const char*> names, int fallback) {
  for (const char* name : names) {
    if (std::optional<Node> n = map.optional(name)) {
      Expected<std::int64_t> v = n->as_int();
      if (!v) return std::unexpected(v.error());
      if (*v <= 0 || *v > 1'000'000) return n->fail("must be a positive pixel count");
      return static_cast<int>(*v);
    }
  }
  return fallback;
}

void write_matrix(std::ostringstream& out, const char* name, int rows, int cols,
                  const double* data) {
  out << name << ": !!opencv-matrix\n   rows: " << rows << "\n   cols: " << cols
      << "\n   dt: d\n   data: [ ";
  for (int i = 0; i < rows * cols; ++i) out << (i ? ", " : "") << format_double(data[i]);
  out << " ]\n";
}

}  // namespace

Expected<Rig> parse_opencv_yaml(std::string_view text, const std::string& name, int width,
                                int height, std::string_view id_prefix,
                                const OpencvImport& options) {
  // cv::FileStorage writes "%YAML:1.0", which is not a valid YAML directive; "%YAML 1.0" is.
  std::string source(text);
  if (source.rfind("%YAML:", 0) == 0) source[5] = ' ';
  Expected<Node> root = parse(source, name);
  if (!root) return std::unexpected(root.error());
  Expected<MapReader> map = MapReader::from(*root);
  if (!map) return std::unexpected(map.error());
  Expected<int> w = find_size(*map, {"image_width", "width"}, width);
  if (!w) return std::unexpected(w.error());
  Expected<int> h = find_size(*map, {"image_height", "height"}, height);
  if (!h) return std::unexpected(h.error());
  if (*w <= 0 || *h <= 0) {
    return root->fail("image size unknown: the file has no image_width/image_height; pass it");
  }

  Rig rig;
  auto add_camera = [&](const MatrixValue& K, const std::optional<MatrixValue>& D,
                        const Rigid3& pose) -> Expected<void> {
    Camera camera;
    camera.id = std::string(id_prefix) + std::to_string(rig.cameras.size());
    camera.width = *w;
    camera.height = *h;
    Expected<Intrinsics> k = to_intrinsics(K);
    if (!k) return std::unexpected(k.error());
    camera.intrinsics = *k;
    Expected<Distortion> d = to_distortion(D);
    if (!d) return std::unexpected(d.error());
    camera.distortion = *d;
    camera.cam_from_world = pose;
    if (options.paper_model) {
      Expected<PaperModelFit> fit = to_paper_model(camera, options.fit);
      if (!fit) return fail(name + ": " + fit.error().message);
      camera = fit->camera;
      if (options.fits != nullptr) options.fits->push_back(std::move(*fit));
    }
    rig.cameras.push_back(std::move(camera));
    return {};
  };

  Expected<std::optional<MatrixValue>> R = find_matrix(*map, {"R"});
  if (!R) return std::unexpected(R.error());
  Expected<std::optional<MatrixValue>> T = find_matrix(*map, {"T", "t"});
  if (!T) return std::unexpected(T.error());
  Expected<Rigid3> pose = to_pose(*R, *T, *root);
  if (!pose) return std::unexpected(pose.error());

  if (map->has("K1") || map->has("K2")) {
    Expected<std::optional<MatrixValue>> K1 = find_matrix(*map, {"K1"});
    if (!K1) return std::unexpected(K1.error());
    Expected<std::optional<MatrixValue>> K2 = find_matrix(*map, {"K2"});
    if (!K2) return std::unexpected(K2.error());
    if (!*K1 || !*K2) return root->fail("stereo file needs both K1 and K2");
    if (!*R) return root->fail("stereo file needs R and T (camera 1 from camera 0)");
    Expected<std::optional<MatrixValue>> D1 = find_matrix(*map, {"D1"});
    if (!D1) return std::unexpected(D1.error());
    Expected<std::optional<MatrixValue>> D2 = find_matrix(*map, {"D2"});
    if (!D2) return std::unexpected(D2.error());
    if (auto ok = add_camera(**K1, *D1, Rigid3::identity()); !ok)
      return std::unexpected(ok.error());
    if (auto ok = add_camera(**K2, *D2, *pose); !ok) return std::unexpected(ok.error());
    return rig;
  }
  Expected<std::optional<MatrixValue>> K = find_matrix(*map, {"K", "camera_matrix"});
  if (!K) return std::unexpected(K.error());
  if (!*K) return root->fail("no camera matrix (expected K, camera_matrix or K1/K2)");
  Expected<std::optional<MatrixValue>> D =
      find_matrix(*map, {"distCoeffs", "D", "distortion_coefficients"});
  if (!D) return std::unexpected(D.error());
  if (auto ok = add_camera(**K, *D, *pose); !ok) return std::unexpected(ok.error());
  return rig;
}

Expected<Rig> import_opencv_yaml(const std::string& path, int width, int height,
                                 std::string_view id_prefix, const OpencvImport& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(path + ": cannot open file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return fail(path + ": read error");
  return parse_opencv_yaml(buffer.str(), path, width, height, id_prefix, options);
}

std::string format_opencv_yaml(const Camera& c) {
  std::ostringstream out;
  out << "%YAML:1.0\n---\n";
  out << "image_width: " << c.width << "\nimage_height: " << c.height << '\n';
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> K = c.intrinsics.K();
  write_matrix(out, "camera_matrix", 3, 3, K.data());
  const Distortion& d = c.distortion;
  double coefficients[5] = {0, 0, 0, 0, 0};
  if (d.model == Distortion::Model::radial) {
    coefficients[0] = d.rd3;
    coefficients[1] = d.rd5;
  } else if (d.model == Distortion::Model::opencv) {
    const double v[5] = {d.k1, d.k2, d.p1, d.p2, d.k3};
    std::copy(v, v + 5, coefficients);
  }
  write_matrix(out, "distortion_coefficients", 1, 5, coefficients);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = c.cam_from_world.R();
  write_matrix(out, "R", 3, 3, R.data());
  write_matrix(out, "T", 3, 1, c.cam_from_world.translation.data());
  return out.str();
}

Expected<void> export_opencv_yaml(const Camera& camera, const std::string& path) {
  if (Expected<void> ok = validate_camera(camera, "camera"); !ok) {
    return fail(path + ": not written: " + ok.error().message);
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return fail(path + ": cannot open for writing");
  out << format_opencv_yaml(camera);
  out.close();
  if (!out) return fail(path + ": write error");
  return {};
}

}  // namespace studio::yaml
