#include "scene/serialize.h"

#include <bit>
#include <cstring>
#include <string>

namespace studio::scene {
namespace {

constexpr char kMagic[8] = {'S', 'T', 'S', 'C', 'E', 'N', 'E', '1'};
constexpr std::size_t kMaxCount = std::size_t{1} << 24;

class Writer {
 public:
  std::vector<std::uint8_t> bytes;
  void u8(std::uint8_t v) { bytes.push_back(v); }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
  void str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  template <class V>
  void vec(const V& v) {
    for (int i = 0; i < v.size(); ++i) {
      if constexpr (std::is_same_v<typename V::Scalar, float>)
        f32(v[i]);
      else
        f64(v[i]);
    }
  }
};

class Reader {
 public:
  explicit Reader(const std::vector<std::uint8_t>& b) : b_(b) {}
  bool ok() const { return ok_; }
  std::size_t remaining() const { return b_.size() - pos_; }
  bool take(std::size_t n) {
    if (!ok_ || remaining() < n) return ok_ = false;
    return true;
  }
  std::uint8_t u8() { return take(1) ? b_[pos_++] : 0; }
  std::uint32_t u32() {
    if (!take(4)) return 0;
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= std::uint32_t{b_[pos_++]} << (8 * i);
    return v;
  }
  std::uint64_t u64() {
    if (!take(8)) return 0;
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= std::uint64_t{b_[pos_++]} << (8 * i);
    return v;
  }
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  double f64() { return std::bit_cast<double>(u64()); }
  float f32() { return std::bit_cast<float>(u32()); }
  std::string str() {
    const std::uint32_t n = u32();
    if (!take(n)) return {};
    std::string s(reinterpret_cast<const char*>(b_.data() + pos_), n);
    pos_ += n;
    return s;
  }
  // A count of items each at least `min_item` bytes long (so a corrupt count cannot allocate).
  std::size_t count(std::size_t min_item) {
    const std::size_t n = u32();
    if (n > kMaxCount || n * min_item > remaining()) ok_ = false;
    return ok_ ? n : 0;
  }
  template <class V>
  void vec(V& v) {
    for (int i = 0; i < v.size(); ++i) {
      if constexpr (std::is_same_v<typename V::Scalar, float>)
        v[i] = f32();
      else
        v[i] = f64();
    }
  }
  bool magic() {
    if (!take(8) || std::memcmp(b_.data(), kMagic, 8) != 0) return ok_ = false;
    pos_ += 8;
    return true;
  }

 private:
  const std::vector<std::uint8_t>& b_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

void write_transform(Writer& w, const Transform& t) {
  w.vec(t.translation);
  w.vec(t.rotation.coeffs());  // x, y, z, w
  w.vec(t.scale);
}

Transform read_transform(Reader& r) {
  Transform t;
  r.vec(t.translation);
  Eigen::Vector4d q;
  r.vec(q);
  t.rotation.coeffs() = q;
  r.vec(t.scale);
  return t;
}

void write_node(Writer& w, const Node& n) {
  w.str(n.id);
  w.str(n.parent);
  w.u8(static_cast<std::uint8_t>(n.kind));
  write_transform(w, n.local);
  w.u8(n.visible ? 1 : 0);
  w.str(n.asset.path);
  w.str(n.asset.sha256);
  w.u32(static_cast<std::uint32_t>(n.asset.meshes.size()));
  for (std::uint32_t m : n.asset.meshes) w.u32(m);
  w.vec(n.material.colour);
  w.str(n.material.texture);
  w.u8(n.material.high_contrast ? 1 : 0);
  w.u8(static_cast<std::uint8_t>(n.light.type));
  w.vec(n.light.colour);
  w.f32(n.light.intensity);
  w.f32(n.light.range);
  w.f32(n.light.inner_cone);
  w.f32(n.light.outer_cone);
  w.str(n.actor_id);
  w.i64(n.frame);
}

Node read_node(Reader& r) {
  Node n;
  n.id = r.str();
  n.parent = r.str();
  n.kind = static_cast<NodeKind>(r.u8());
  n.local = read_transform(r);
  n.visible = r.u8() != 0;
  n.asset.path = r.str();
  n.asset.sha256 = r.str();
  n.asset.meshes.resize(r.count(4));
  for (auto& m : n.asset.meshes) m = r.u32();
  r.vec(n.material.colour);
  n.material.texture = r.str();
  n.material.high_contrast = r.u8() != 0;
  n.light.type = static_cast<LightType>(r.u8());
  r.vec(n.light.colour);
  n.light.intensity = r.f32();
  n.light.range = r.f32();
  n.light.inner_cone = r.f32();
  n.light.outer_cone = r.f32();
  n.actor_id = r.str();
  n.frame = r.i64();
  return n;
}

}  // namespace

std::uint64_t fnv1a64(const std::uint8_t* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

std::vector<std::uint8_t> serialize(const Scene& scene) {
  Writer w;
  w.bytes.insert(w.bytes.end(), kMagic, kMagic + 8);
  w.f64(scene.options().frame_period);
  w.i64(scene.frame());
  w.u32(static_cast<std::uint32_t>(scene.nodes().size()));
  for (const auto& [id, n] : scene.nodes()) write_node(w, n);
  w.u32(static_cast<std::uint32_t>(scene.animations().size()));
  for (const auto& [name, e] : scene.animations()) {
    w.str(e.animation.name);
    w.u8(static_cast<std::uint8_t>(e.animation.mode));
    w.u32(static_cast<std::uint32_t>(e.animation.tracks.size()));
    for (const Track& t : e.animation.tracks) {
      w.str(t.node);
      w.u8(static_cast<std::uint8_t>(t.path));
      w.u8(static_cast<std::uint8_t>(t.interpolation));
      w.u32(static_cast<std::uint32_t>(t.times.size()));
      for (std::size_t k = 0; k < t.times.size(); ++k) {
        w.f64(t.times[k]);
        w.vec(t.values[k]);
      }
    }
    w.u8(e.clock.playing ? 1 : 0);
    w.f64(e.clock.speed);
    w.i64(e.clock.anchor_frame);
    w.f64(e.clock.anchor_time);
  }
  return std::move(w.bytes);
}

Expected<Scene> deserialize(const std::vector<std::uint8_t>& bytes) {
  Reader r(bytes);
  if (!r.magic()) return fail("scene state: not a scene state (bad magic)");
  SceneOptions options;
  options.frame_period = r.f64();
  if (auto ok = options.validate(); r.ok() && !ok) return fail("scene state: " + ok.error().message);
  Scene scene(options);
  scene.frame_ = r.i64();
  const std::size_t n_nodes = r.count(64);
  for (std::size_t i = 0; i < n_nodes && r.ok(); ++i) {
    Node n = read_node(r);
    if (!r.ok()) break;
    const NodeId id = n.id;
    if (!scene.nodes_.emplace(id, std::move(n)).second)
      return fail("scene state: node '" + id + "' appears twice");
  }
  const std::size_t n_anim = r.count(16);
  for (std::size_t i = 0; i < n_anim && r.ok(); ++i) {
    AnimationEntry e;
    e.animation.name = r.str();
    e.animation.mode = static_cast<PlayMode>(r.u8());
    e.animation.tracks.resize(r.count(10));
    for (Track& t : e.animation.tracks) {
      t.node = r.str();
      t.path = static_cast<TrackPath>(r.u8());
      t.interpolation = static_cast<Interpolation>(r.u8());
      const std::size_t keys = r.count(40);
      t.times.resize(keys);
      t.values.resize(keys);
      for (std::size_t k = 0; k < keys; ++k) {
        t.times[k] = r.f64();
        r.vec(t.values[k]);
      }
    }
    e.clock.playing = r.u8() != 0;
    e.clock.speed = r.f64();
    e.clock.anchor_frame = r.i64();
    e.clock.anchor_time = r.f64();
    if (!r.ok()) break;
    const std::string name = e.animation.name;
    if (!scene.animations_.emplace(name, std::move(e)).second)
      return fail("scene state: animation '" + name + "' appears twice");
  }
  if (!r.ok()) return fail("scene state: truncated or corrupt");
  if (r.remaining() != 0) return fail("scene state: " + std::to_string(r.remaining()) + " trailing bytes");
  scene.rebuild_order();
  if (auto ok = scene.check_invariants(); !ok) return fail("scene state: " + ok.error().message);
  // A restored scene publishes every node once.
  for (const auto& [id, n] : scene.nodes_) scene.updated_.insert(id);
  return scene;
}

}  // namespace studio::scene
