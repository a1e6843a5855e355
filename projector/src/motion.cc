#include "projector/motion.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "text.h"

namespace studio::projector {
namespace {

int64_t cell_key(const Eigen::Vector3i& c) {
  constexpr int64_t kOffset = 1 << 20;
  return ((c.x() + kOffset) << 42) | ((c.y() + kOffset) << 21) | (c.z() + kOffset);
}

// Uniform grid over a mesh's vertices for nearest-vertex queries: dense over the vertices'
// bounding box (cell lists in one array, counting sort), so a query costs a few array reads.
class VertexGrid {
 public:
  VertexGrid(const std::vector<Eigen::Vector3f>& points, double cell)
      : points_(points), cell_(cell) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (const auto& q : points) {
      lo = lo.cwiseMin(q.cast<double>());
      hi = hi.cwiseMax(q.cast<double>());
    }
    if (points.empty()) lo = hi = Eigen::Vector3d::Zero();
    // At most ~4M cells (two actors at opposite corners of a large studio): coarser cells then.
    while (true) {
      dims_ = ((hi - lo) / cell_).array().floor().cast<int>() + 1;
      if (double(dims_.x()) * dims_.y() * dims_.z() <= 4e6) break;
      cell_ *= 1.5;
    }
    lo_ = lo;
    start_.assign(size_t(dims_.x()) * dims_.y() * dims_.z() + 1, 0);
    std::vector<int> cell_of_point(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      cell_of_point[i] = index(cell_of(points[i].cast<double>()));
      ++start_[cell_of_point[i] + 1];
    }
    for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    order_.resize(points.size());
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < points.size(); ++i) order_[fill[cell_of_point[i]]++] = int(i);
  }

  // Index of the nearest point within max_distance, or -1.
  int nearest(const Eigen::Vector3d& p, double max_distance) const {
    const Eigen::Vector3d g = (p - lo_) / cell_;
    const Eigen::Vector3i c = g.array().floor().cast<int>();
    // Distance from p to the nearest face of its own cell: every point outside the cube of
    // shells 0..k is at least k cells + this far away.
    const Eigen::Vector3d f = g - c.cast<double>();
    const double wall = cell_ * std::min({f.x(), 1 - f.x(), f.y(), 1 - f.y(), f.z(), 1 - f.z()});
    // Beyond this shell there are no cells.
    const int last = ((c.array()).abs().max((c.array() - dims_.array() + 1).abs())).maxCoeff();
    const int shells = std::min(last, static_cast<int>(std::ceil(max_distance / cell_)));
    int best = -1;
    double best_d2 = max_distance * max_distance;
    auto scan = [&](int x, int y, int z) {
      const int cell = index({x, y, z});
      for (int j = start_[cell]; j < start_[cell + 1]; ++j) {
        const int i = order_[j];
        const double d2 = (points_[i].cast<double>() - p).squaredNorm();
        if (d2 < best_d2) {
          best_d2 = d2;
          best = i;
        }
      }
    };
    for (int k = 0; k <= shells; ++k) {
      // The cells of shell k (Chebyshev distance k from c) inside the grid.
      const Eigen::Vector3i a = (c.array() - k).max(0), b = (c.array() + k).min(dims_.array() - 1);
      for (int x = a.x(); x <= b.x(); ++x)
        for (int y = a.y(); y <= b.y(); ++y) {
          if (std::max(std::abs(x - c.x()), std::abs(y - c.y())) == k) {
            for (int z = a.z(); z <= b.z(); ++z) scan(x, y, z);
          } else {
            const int below = c.z() - k, above = c.z() + k;
            if (below >= a.z() && below <= b.z()) scan(x, y, below);
            if (k > 0 && above >= a.z() && above <= b.z()) scan(x, y, above);
          }
        }
      const double reach = k * cell_ + wall;
      if (best >= 0 && best_d2 <= reach * reach) break;
    }
    return best;
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    return ((p - lo_) / cell_).array().floor().cast<int>().max(0).min(dims_.array() - 1);
  }
  int index(const Eigen::Vector3i& c) const {
    return (c.x() * dims_.y() + c.y()) * dims_.z() + c.z();
  }
  const std::vector<Eigen::Vector3f>& points_;
  double cell_;
  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
  std::vector<int> start_, order_;
};

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection §5.1.5).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace

// The previous mesh as ICP's target: nearest vertex by grid, then the closest point on the
// triangles around it, with that triangle's normal (point-to-triangle: no bias from
// tessellations that differ from frame to frame). Built once per mesh; never moved (the grid
// refers to the mesh's vertices).
class MotionTarget {
 public:
  MotionTarget(ActorMesh m, double cell) : mesh(std::move(m)), grid(mesh.vertices, cell) {
    // Triangles per vertex in one array (counting sort: first_triangle[v] .. [v + 1]), not a
    // vector per vertex: ~10k allocations per mesh less.
    first_triangle.assign(mesh.vertices.size() + 1, 0);
    for (const auto& tri : mesh.triangles)
      for (uint32_t v : tri) ++first_triangle[v + 1];
    for (size_t v = 1; v < first_triangle.size(); ++v) first_triangle[v] += first_triangle[v - 1];
    triangle_list.resize(first_triangle.back());
    std::vector<int> fill(first_triangle.begin(), first_triangle.end() - 1);
    face_normals.resize(mesh.triangles.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& tri = mesh.triangles[t];
      const Eigen::Vector3d a = mesh.vertices[tri[0]].cast<double>();
      const Eigen::Vector3d n = (mesh.vertices[tri[1]].cast<double>() - a)
                                    .cross(mesh.vertices[tri[2]].cast<double>() - a);
      face_normals[t] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
      for (uint32_t v : tri) triangle_list[fill[v]++] = static_cast<int>(t);
    }
  }
  MotionTarget(const MotionTarget&) = delete;
  MotionTarget& operator=(const MotionTarget&) = delete;

  // Closest surface point and its normal; false when no vertex is within max_distance.
  bool closest(const Eigen::Vector3d& p, double max_distance, Eigen::Vector3d* point,
               Eigen::Vector3d* normal) const {
    const int q = grid.nearest(p, max_distance);
    if (q < 0) return false;
    double best = INFINITY;
    for (int k = first_triangle[q]; k < first_triangle[q + 1]; ++k) {
      const int t = triangle_list[k];
      if (face_normals[t].squaredNorm() < 0.5) continue;
      const auto& tri = mesh.triangles[t];
      const Eigen::Vector3d c = closest_on_triangle(p, mesh.vertices[tri[0]].cast<double>(),
                                                    mesh.vertices[tri[1]].cast<double>(),
                                                    mesh.vertices[tri[2]].cast<double>());
      const double d = (c - p).squaredNorm();
      if (d < best) {
        best = d;
        *point = c;
        *normal = face_normals[t];
      }
    }
    return std::isfinite(best);
  }

  const ActorMesh mesh;
  const VertexGrid grid;
  std::vector<int> first_triangle, triangle_list;  // triangles around each vertex
  std::vector<Eigen::Vector3d> face_normals;
};

namespace {

using Target = MotionTarget;

double grid_cell(const MotionOptions& options) {
  return std::max(0.01, options.max_correspondence_m / 8);
}

// A stratified sample of at most `budget` of `indices` (every k-th, evenly over the list; the
// hull's vertex order is spatially coherent); budget 0: all of them.
std::vector<int> stratified(const std::vector<int>& indices, int budget) {
  if (budget <= 0 || indices.size() <= size_t(budget)) return indices;
  std::vector<int> out(static_cast<size_t>(budget));
  const double step = double(indices.size()) / budget;
  for (int k = 0; k < budget; ++k) out[k] = indices[size_t((k + 0.5) * step)];
  return out;
}

struct Fit {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // sum n n^T of the last iteration
  double rms = 0;
  int used = 0;
  int iterations = 0;       // run
  int64_t queries = 0;      // closest-point queries
};

// Point-to-plane ICP of the translation t with current = previous moved by t, over the current
// vertices `indices`, damped towards `prior`.
// `weight` scales the information of the result (members / sample of a subsampled fit).
Fit icp_translation(const ActorMesh& current, const std::vector<int>& indices, const Target& target,
                    const Eigen::Vector3d& start, const Eigen::Vector3d& prior,
                    const MotionOptions& options, double weight = 1) {
  Fit fit;
  fit.translation = start;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    ++fit.iterations;
    fit.queries += int64_t(indices.size());
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    double sum = 0;
    int used = 0;
    for (int i : indices) {
      const Eigen::Vector3d p = current.vertices[i].cast<double>() - fit.translation;
      Eigen::Vector3d q = Eigen::Vector3d::Zero(), n = Eigen::Vector3d::Zero();
      if (!target.closest(p, options.max_correspondence_m, &q, &n)) continue;
      const double r = n.dot(p - q);
      a += n * n.transpose();
      b += n * r;
      sum += r * r;
      ++used;
    }
    fit.used = used;
    fit.information = weight * a;
    if (used < 3) break;
    fit.rms = std::sqrt(sum / used);
    const double lambda = options.damping * a.trace() / 3;
    // r(t + d) = r - n . d: minimise sum (r - n.d)^2 + lambda |t + d - prior|^2.
    const Eigen::Vector3d delta = (a + lambda * Eigen::Matrix3d::Identity())
                                      .ldlt()
                                      .solve(b - lambda * (fit.translation - prior));
    if (!delta.allFinite()) break;
    fit.translation += delta;
    if (delta.norm() < options.converged_m) break;
  }
  return fit;
}

// previous: target.mesh, already validated.
Expected<MeshMotion> estimate(const Target& target, const ActorMesh& current,
                              const MotionOptions& options, const MeshMotion* previous_motion) {
  const ActorMesh& previous = target.mesh;
  const double dt = 1e-9 * static_cast<double>(current.capture_ns - previous.capture_ns);
  if (!(dt > 0))
    return fail(text("motion: the meshes' capture times do not increase (dt %.6f s)", dt));
  if (dt > options.max_dt_s)
    return fail(
        text("motion: the meshes are %.3f s apart (more than %.3f s)", dt, options.max_dt_s));

  const std::vector<Eigen::Vector3f> current_normals = vertex_normals(current);
  MeshMotion motion;
  motion.dt_s = dt;

  std::vector<int> all(current.vertices.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const Fit global = icp_translation(current, stratified(all, options.global_fit_vertices), target,
                                     Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), options);
  motion.global_velocity = global.translation / dt;
  auto count = [&motion](const Fit& fit) {
    ++motion.fits;
    motion.iterations += fit.iterations;
    motion.closest_queries += fit.queries;
  };
  count(global);

  std::unordered_map<int64_t, int> region_of_cell;
  std::vector<Eigen::Vector3i> region_cell;
  std::vector<std::vector<int>> members;
  motion.vertex_region.resize(current.vertices.size());
  for (size_t i = 0; i < current.vertices.size(); ++i) {
    const Eigen::Vector3i c =
        (current.vertices[i].cast<double>() / options.region_size_m).array().floor().cast<int>();
    auto [it, inserted] = region_of_cell.emplace(cell_key(c), static_cast<int>(members.size()));
    if (inserted) {
      members.emplace_back();
      region_cell.push_back(c);
    }
    members[it->second].push_back(static_cast<int>(i));
    motion.vertex_region[i] = it->second;
  }
  motion.regions.resize(members.size());
  std::vector<bool> fitted(members.size(), false);
  std::vector<Eigen::Vector3d> translation(members.size(), global.translation);
  std::vector<Eigen::Matrix3d> information(members.size(), Eigen::Matrix3d::Zero());
  for (size_t r = 0; r < members.size(); ++r) {
    RegionMotion& region = motion.regions[r];
    region.vertices = static_cast<int>(members[r].size());
    for (int i : members[r]) region.centre += current.vertices[i].cast<double>();
    region.centre /= region.vertices;
    for (int i : members[r]) region.normal += current_normals[i].cast<double>();
    region.normal /= region.vertices;
    if (region.vertices < options.min_region_vertices) continue;
    // Started from, and damped towards, the whole mesh's translation (the convergence basin);
    // what the region sees weakly or not at all is replaced below.
    const std::vector<int> sample = stratified(members[r], options.fit_vertices);
    const Fit fit = icp_translation(current, sample, target, global.translation, global.translation,
                                    options, double(members[r].size()) / double(sample.size()));
    count(fit);
    if (fit.used < std::min<int>(sample.size(), options.min_region_vertices) / 2) continue;
    translation[r] = fit.translation;
    information[r] = fit.information;
    region.rms_m = fit.rms;
    region.fitted = true;
    fitted[r] = true;
  }
  // What a region cannot see comes from the smallest enclosing cell (2, 4, 8 ... region sizes,
  // then the whole mesh) whose fitted regions together see every direction: the
  // information-weighted combination t_cell = A^-1 sum_k A_k t_k, A = sum_k A_k, if they agree on
  // it (else those directions stay still). A translation seen only by several surfaces together
  // (the faces of a moving box) is recovered; a cell that mixes a moving hand with a still torso
  // lends nothing. The region keeps its own estimate along the directions it sees (eigenvectors
  // of A_r with at least weak_direction of the largest eigenvalue) and takes the cell's along the
  // others.
  constexpr int kLevels = 8;
  struct Sum {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();  // sum A_k
    Eigen::Vector3d b = Eigen::Vector3d::Zero();  // sum A_k t_k
    double tat = 0;                               // sum t_k^T A_k t_k
    void add(const Eigen::Matrix3d& ak, const Eigen::Vector3d& tk) {
      a += ak;
      b += ak * tk;
      tat += tk.dot(ak * tk);
    }
  };
  std::array<std::unordered_map<int64_t, Sum>, kLevels> sums;
  Sum whole_sum;
  for (size_t r = 0; r < members.size(); ++r) {
    if (!fitted[r]) continue;
    whole_sum.add(information[r], translation[r]);
    for (int level = 1; level < kLevels; ++level) {
      const Eigen::Vector3i c(region_cell[r].x() >> level, region_cell[r].y() >> level,
                              region_cell[r].z() >> level);
      sums[level][cell_key(c)].add(information[r], translation[r]);
    }
  }
  auto eigenvalues = [](const Eigen::Matrix3d& a) {
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(a, Eigen::EigenvaluesOnly).eigenvalues();
  };
  // A cell's combined translation, when its regions see every direction together and agree on
  // one translation (RMS disagreement sum (t_k - t)^T A_k (t_k - t) / sum tr A_k within
  // consistency_m): a cell holding a moving hand and a still torso gives nothing.
  auto combined = [&](const Sum& sum) -> std::optional<Eigen::Vector3d> {
    const Eigen::Vector3d e = eigenvalues(sum.a);
    if (!(e(2) > 0) || e(0) < options.weak_direction * e(2)) return std::nullopt;
    const Eigen::Vector3d t = sum.a.ldlt().solve(sum.b);
    const double disagreement = std::max(0.0, sum.tat - t.dot(sum.b)) / sum.a.trace();
    if (!t.allFinite() || disagreement > options.consistency_m * options.consistency_m)
      return std::nullopt;
    return t;
  };
  const std::optional<Eigen::Vector3d> whole = combined(whole_sum);
  for (size_t r = 0; r < members.size(); ++r) {
    if (!fitted[r]) continue;
    // Unseen directions stay still unless a consistent enclosing cell says otherwise.
    Eigen::Vector3d prior = Eigen::Vector3d::Zero();
    const Eigen::Vector3d e = eigenvalues(information[r]);
    if (e(0) < options.weak_direction * e(2)) {
      bool found = false;
      for (int level = 1; level < kLevels && !found; ++level) {
        const Eigen::Vector3i c(region_cell[r].x() >> level, region_cell[r].y() >> level,
                                region_cell[r].z() >> level);
        const Sum& sum = sums[level].at(cell_key(c));
        const Eigen::Vector3d ec = eigenvalues(sum.a);
        if (ec(0) < options.weak_direction * ec(2)) continue;  // not yet every direction: go up
        if (auto t = combined(sum)) prior = *t;
        found = true;  // the smallest cell that sees everything decides, consistent or not
      }
      if (!found && whole) prior = *whole;
    }
    // Seen directions (eigenvalue >= weak_direction of the largest) from the region's own fit,
    // the others from the prior.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(information[r]);
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d v = es.eigenvectors().col(i);
      const bool seen = es.eigenvalues()(i) >= options.weak_direction * es.eigenvalues()(2);
      t += v * v.dot(seen ? translation[r] : prior);
    }
    motion.regions[r].velocity = t / dt;
  }
  for (size_t r = 0; r < members.size(); ++r)
    if (!fitted[r]) motion.regions[r].velocity = global.translation / dt;
  // A region too small to fit (a few vertices in the corner of a cell) moves with the nearest
  // fitted region within 1.5 region sizes (the same body part, most likely), else with the mesh.
  for (size_t r = 0; r < members.size(); ++r) {
    if (fitted[r]) continue;
    double best = 1.5 * options.region_size_m;
    for (size_t o = 0; o < members.size(); ++o) {
      if (!fitted[o]) continue;
      const double d = (motion.regions[o].centre - motion.regions[r].centre).norm();
      if (d < best) {
        best = d;
        motion.regions[r].velocity = motion.regions[o].velocity;
      }
    }
  }
  for (const RegionMotion& region : motion.regions)
    motion.max_speed_mps = std::max(motion.max_speed_mps, region.velocity.norm());

  // Accelerations: the previous estimate's region that, moved by its velocity, lands nearest.
  if (previous_motion != nullptr && !previous_motion->regions.empty()) {
    const double between = 0.5 * (dt + previous_motion->dt_s);  // between the two mean velocities
    for (RegionMotion& region : motion.regions) {
      if (!region.fitted) continue;
      const RegionMotion* match = nullptr;
      double best = options.region_size_m;
      for (const RegionMotion& old : previous_motion->regions) {
        if (!old.fitted) continue;
        const double d = (old.centre + old.velocity * dt - region.centre).norm();
        if (d < best) {
          best = d;
          match = &old;
        }
      }
      if (match == nullptr) continue;
      region.acceleration = (region.velocity - match->velocity) / between;

      // What moves the mask is the surface's motion along its normal: the acceleration along the
      // region's mean normal (all of it where the region has no dominant normal).
      const double along = region.normal.norm() > 0.5
                               ? std::abs(region.acceleration->dot(region.normal.normalized()))
                               : region.acceleration->norm();
      motion.max_acceleration_mps2 = std::max(motion.max_acceleration_mps2.value_or(0), along);
    }
  }
  return motion;
}

}  // namespace

Expected<void> MotionOptions::validate() const {
  if (!(region_size_m > 0) || !std::isfinite(region_size_m))
    return fail("motion: region_size_m must be > 0");
  if (iterations < 1) return fail("motion: iterations must be >= 1");
  if (acceleration_window < 1 || acceleration_window > 100)
    return fail("motion: acceleration_window must be 1..100");
  if (!(converged_m > 0) || !std::isfinite(converged_m))
    return fail("motion: converged_m must be > 0");
  if (fit_vertices < 0 || (fit_vertices > 0 && fit_vertices < min_region_vertices))
    return fail("motion: fit_vertices must be 0 (all) or >= min_region_vertices");
  if (global_fit_vertices < 0 || (global_fit_vertices > 0 && global_fit_vertices < 3))
    return fail("motion: global_fit_vertices must be 0 (all) or >= 3");
  if (!(max_correspondence_m > 0) || !std::isfinite(max_correspondence_m))
    return fail("motion: max_correspondence_m must be > 0");
  if (!(damping >= 0) || !std::isfinite(damping)) return fail("motion: damping must be >= 0");
  if (min_region_vertices < 3) return fail("motion: min_region_vertices must be >= 3");
  if (!(max_dt_s > 0)) return fail("motion: max_dt_s must be > 0");
  return {};
}

namespace {
Expected<void> check_pair(const ActorMesh& previous, const ActorMesh& current,
                          const MotionOptions& options) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  if (auto v = previous.validate(); !v) return fail("motion: previous " + v.error().message);
  if (auto v = current.validate(); !v) return fail("motion: current " + v.error().message);
  return {};
}
}  // namespace

Expected<MeshMotion> estimate_motion(const ActorMesh& previous, const ActorMesh& current,
                                     const MotionOptions& options) {
  if (auto ok = check_pair(previous, current, options); !ok) return std::unexpected(ok.error());
  const MotionTarget target(previous, grid_cell(options));
  return estimate(target, current, options, nullptr);
}

MotionTracker::MotionTracker(MotionOptions options) : options_(std::move(options)) {}
MotionTracker::~MotionTracker() = default;
MotionTracker::MotionTracker(MotionTracker&&) noexcept = default;
MotionTracker& MotionTracker::operator=(MotionTracker&&) noexcept = default;

Expected<std::optional<MeshMotion>> MotionTracker::update(const ActorMesh& mesh) {
  if (auto v = mesh.validate(); !v) {
    reset();
    return std::unexpected(v.error());
  }
  if (auto v = options_.validate(); !v) return std::unexpected(v.error());
  if (last_ && mesh.capture_ns <= last_->mesh.capture_ns)
    return fail("motion: a mesh no newer than the last one (ignored)");
  std::optional<MeshMotion> motion;
  if (last_ &&
      1e-9 * static_cast<double>(mesh.capture_ns - last_->mesh.capture_ns) <= options_.max_dt_s) {
    auto m = estimate(*last_, mesh, options_, last_motion_ ? &*last_motion_ : nullptr);
    if (!m) {
      reset();
      return std::unexpected(m.error());
    }
    motion = std::move(*m);
    if (motion->max_acceleration_mps2) {
      accelerations_.push_back(*motion->max_acceleration_mps2);
      while (accelerations_.size() > std::size_t(options_.acceleration_window))
        accelerations_.erase(accelerations_.begin());
      std::vector<double> sorted = accelerations_;
      std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
      double robust = sorted[sorted.size() / 2];
      // An acceleration two consecutive estimates agree on is taken at once: the median alone
      // lags the onset of a motion by half the window, which at a projector's few meshes a
      // second is longer than the acceleration phase itself (a 60 s demo left 183 px lit).
      if (accelerations_.size() >= 2)
        robust = std::max(robust, std::min(accelerations_.back(), accelerations_.end()[-2]));
      motion->robust_acceleration_mps2 = robust;
    }
  }
  // This mesh is the next one's target: its structure is built once, here.
  last_ = std::make_unique<MotionTarget>(mesh, grid_cell(options_));
  last_motion_ = std::move(motion);
  return last_motion_;
}

void MotionTracker::reset() {
  last_.reset();
  last_motion_.reset();
  accelerations_.clear();
}

Expected<ActorMesh> predict(const ActorMesh& mesh, const MeshMotion& motion, double horizon_s) {
  if (motion.vertex_region.size() != mesh.vertices.size())
    return fail(text("predict: the motion has %zu vertices, the mesh %zu",
                     motion.vertex_region.size(), mesh.vertices.size()));
  if (!(horizon_s >= 0) || !std::isfinite(horizon_s)) return fail("predict: horizon must be >= 0");
  ActorMesh out = mesh;
  const float h = static_cast<float>(horizon_s);
  for (size_t i = 0; i < out.vertices.size(); ++i) out.vertices[i] += h * motion.velocity(i);
  return out;
}

}  // namespace studio::projector
