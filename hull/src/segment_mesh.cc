#include "hull/segment_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <unordered_map>

namespace studio::hull {
namespace {

// Vertical lines of the padded lattice in doubled coordinates: column (i, j) is (2i+2, 2j+2),
// mid-edges and cell centres sit at odd coordinates; i, j run from -1 (the empty ring) up.
struct Lattice {
  int nu, nv;  // columns
  int X, Y;    // lattice size
  Lattice(int nu_, int nv_) : nu(nu_), nv(nv_), X(2 * nu_ + 3), Y(2 * nv_ + 3) {}
  std::size_t line(int x2, int y2) const { return std::size_t(x2) + std::size_t(y2) * X; }
};

// Marching-squares pieces of a cell: T_k = (m_{k-1}, c_k, m_k) (bits 0-3), D_k = (o, m_{k-1},
// m_k) (bits 4-7), both counter-clockwise. Corners c0..c3 = (i,j), (i+1,j), (i+1,j+1), (i,j+1);
// m_k is the midpoint of c_k c_{k+1}; o the centre.
constexpr uint8_t pieces(unsigned config) {
  uint8_t p = uint8_t(config & 15u);
  const int n = int(((config >> 0) & 1) + ((config >> 1) & 1) + ((config >> 2) & 1) + ((config >> 3) & 1));
  if (n >= 3) {
    p |= 0xF0;
  } else if (n == 2) {
    for (int k = 0; k < 4; ++k) {
      const unsigned pair = (1u << k) | (1u << ((k + 1) & 3));
      if (config == pair) p |= uint8_t((1u << (4 + k)) | (1u << (4 + ((k + 1) & 3))));
    }
  }
  return p;
}

// Internal piece edges q = 0..3: T_q | D_q; q = 4..7: D_{q-4} | D_{q-3}. +1 when the first piece
// is inside and the second not, -1 for the reverse, 0 when the edge is no contour edge.
constexpr int contour(uint8_t p, int q) {
  const bool x = (p >> q) & 1;
  const bool y = q < 4 ? (p >> (4 + q)) & 1 : (p >> (4 + ((q - 3) & 3))) & 1;
  return x == y ? 0 : (x ? 1 : -1);
}

// Per corner configuration: its pieces and contour directions (tables instead of bit fiddling
// at every event).
struct Tables {
  uint8_t pieces[16];
  int8_t dir[16][8];
};
constexpr Tables make_tables() {
  Tables t{};
  for (unsigned c = 0; c < 16; ++c) {
    t.pieces[c] = pieces(c);
    for (int q = 0; q < 8; ++q) t.dir[c][q] = int8_t(contour(t.pieces[c], q));
  }
  return t;
}
constexpr Tables kTables = make_tables();

}  // namespace

double Mesh::volume() const {
  double v = 0;
  for (const auto& t : triangles) {
    const Eigen::Vector3d a = vertices[t[0]].cast<double>(), b = vertices[t[1]].cast<double>(),
                          c = vertices[t[2]].cast<double>();
    v += a.dot(b.cross(c));
  }
  return v / 6.0;
}

void compute_normals(Mesh& mesh) {
  // Area-weighted vertex normals (float: the cells are centimetres, the sums stay well scaled).
  std::vector<Eigen::Vector3f>& acc = mesh.normals;
  acc.assign(mesh.vertices.size(), Eigen::Vector3f::Zero());
  const Eigen::Vector3f* v = mesh.vertices.data();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f a = v[t[0]];
    const Eigen::Vector3f n = (v[t[1]] - a).cross(v[t[2]] - a);
    acc[t[0]] += n;
    acc[t[1]] += n;
    acc[t[2]] += n;
  }
  for (Eigen::Vector3f& n : acc) {
    const float len = n.norm();
    n = len > 0 ? Eigen::Vector3f(n / len) : Eigen::Vector3f::Zero();
  }
}

Mesh segment_marching_cubes(const SegmentSet& set) {
  const GridSpec& g = set.grid();
  const int nu = g.cells_u, nv = g.cells_v;
  const Lattice L(nu, nv);
  const auto column = [&](int i, int j) -> std::span<const Interval> {
    if (i < 0 || j < 0 || i >= nu || j >= nv) return {};
    return set.column(i, j);
  };

  // Heights on every lattice line: the end points of the columns whose cells touch the line.
  const std::size_t lines = std::size_t(L.X) * L.Y;
  std::vector<uint32_t> offset(lines + 1, 0);
  const auto for_lines_of_column = [&](int i, int j, auto&& f) {
    const int x = 2 * i + 2, y = 2 * j + 2;
    f(L.line(x, y));
    for (int di : {-1, 1})
      for (int dj : {-2, 0, 2}) f(L.line(x + di, y + dj));  // mid-edges along u
    for (int di : {-2, 0, 2})
      for (int dj : {-1, 1}) f(L.line(x + di, y + dj));  // mid-edges along v
    for (int di : {-1, 1})
      for (int dj : {-1, 1}) f(L.line(x + di, y + dj));  // cell centres
  };
  // Occupancy of the columns with the empty ring, (i + 1) + (j + 1) * (nu + 2): empty cells are
  // skipped with four byte loads.
  const std::size_t ow = std::size_t(nu) + 2;
  std::vector<uint8_t> occupied(ow * (std::size_t(nv) + 2), 0);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const uint32_t n = uint32_t(2 * set.column(i, j).size());
      if (!n) continue;
      occupied[std::size_t(i + 1) + std::size_t(j + 1) * ow] = 1;
      for_lines_of_column(i, j, [&](std::size_t l) { offset[l + 1] += n; });
    }
  for (std::size_t l = 0; l < lines; ++l) offset[l + 1] += offset[l];
  std::vector<float> heights(offset.back());
  std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const auto col = set.column(i, j);
      if (col.empty()) continue;
      for_lines_of_column(i, j, [&](std::size_t l) {
        for (const Interval& iv : col) {
          heights[fill[l]++] = iv.lo;
          heights[fill[l]++] = iv.hi;
        }
      });
    }
  std::vector<uint32_t> count(lines, 0);
  for (std::size_t l = 0; l < lines; ++l) {
    float* b = heights.data() + offset[l];
    float* e = heights.data() + offset[l + 1];
    if (b == e) continue;
    if (e - b <= 24) {  // a handful of end points: insertion sort
      for (float* p = b + 1; p < e; ++p) {
        const float x = *p;
        float* q = p;
        for (; q > b && q[-1] > x; --q) *q = q[-1];
        *q = x;
      }
    } else {
      std::sort(b, e);
    }
    count[l] = uint32_t(std::unique(b, e) - b);
  }
  std::vector<int32_t> vertex_of(heights.size(), -1);

  Mesh mesh;
  mesh.vertices.reserve(heights.size() / 2);
  mesh.triangles.reserve(heights.size() + heights.size() / 2);
  const double du = g.du(), dv = g.dv();
  const int ua = g.u(), va = g.v(), aa = g.a();
  // The vertex at heights[slot] of line l (created on first use).
  const auto vertex_at = [&](std::size_t l, std::size_t slot) -> uint32_t {
    int32_t& id = vertex_of[slot];
    if (id < 0) {
      const float t = heights[slot];
      id = int32_t(mesh.vertices.size());
      const int x2 = int(l % std::size_t(L.X)), y2 = int(l / std::size_t(L.X));
      Eigen::Vector3d p;
      p[ua] = g.box_min[ua] + (x2 * 0.5 - 0.5) * du;
      p[va] = g.box_min[va] + (y2 * 0.5 - 0.5) * dv;
      p[aa] = t;
      mesh.vertices.push_back(p.cast<float>());
    }
    return uint32_t(id);
  };
  const auto vertex = [&](std::size_t l, float t) -> uint32_t {
    const float* b = heights.data() + offset[l];
    const uint32_t n = count[l];
    uint32_t k = 0;
    if (n <= 16) {
      while (k < n && b[k] < t) ++k;
    } else {
      k = uint32_t(std::lower_bound(b, b + n, t) - b);
    }
    return vertex_at(l, offset[l] + k);
  };

  // Per cell: lattice lines of corners, mid-edges and centre (doubled offsets from c0).
  static constexpr int kCorner[4][2] = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  static constexpr int kMid[4][2] = {{1, 0}, {2, 1}, {1, 2}, {0, 1}};
  std::vector<float> events;
  std::vector<uint32_t> side_a, side_b;
  for (int cj = -1; cj < nv; ++cj) {
    const uint8_t* occ0 = occupied.data() + std::size_t(cj + 1) * ow;
    const uint8_t* occ1 = occ0 + ow;
    for (int ci = -1; ci < nu; ++ci) {
      if (!(occ0[ci + 1] | occ0[ci + 2] | occ1[ci + 1] | occ1[ci + 2])) continue;
      const std::span<const Interval> cols[4] = {column(ci, cj), column(ci + 1, cj),
                                                 column(ci + 1, cj + 1), column(ci, cj + 1)};
      if (cols[0].empty() && cols[1].empty() && cols[2].empty() && cols[3].empty()) continue;
      events.clear();
      for (const auto& c : cols)
        for (const Interval& iv : c) {
          events.push_back(iv.lo);
          events.push_back(iv.hi);
        }
      std::sort(events.begin(), events.end());
      events.erase(std::unique(events.begin(), events.end()), events.end());
      const int x0 = 2 * ci + 2, y0 = 2 * cj + 2;
      std::size_t corner_line[4], mid_line[4];
      for (int k = 0; k < 4; ++k) {
        corner_line[k] = L.line(x0 + kCorner[k][0], y0 + kCorner[k][1]);
        mid_line[k] = L.line(x0 + kMid[k][0], y0 + kMid[k][1]);
      }
      const std::size_t centre_line = L.line(x0 + 1, y0 + 1);
      // Internal piece edges q = 0..3: T_q | D_q, line pair (m_{q-1}, m_q);
      // q = 4..7: D_{q-4} | D_{q-3}, line pair (o, m_{q-4}).
      const auto edge_lines = [&](int q, int dir, std::size_t* a, std::size_t* b) {
        std::size_t p0, p1;  // direction with the first piece (T_q or D_{q-4}) inside
        if (q < 4) {
          p0 = mid_line[q], p1 = mid_line[(q + 3) & 3];  // T_q inside: m_q -> m_{q-1}
        } else {
          p0 = mid_line[q - 4], p1 = centre_line;  // D_k inside: m_k -> o
        }
        if (dir > 0) *a = p0, *b = p1; else *a = p1, *b = p0;
      };
      const auto emit_wall = [&](int q, int dir, float t0, float t1) {
        std::size_t a, b;
        edge_lines(q, dir, &a, &b);
        const auto collect = [&](std::size_t l, std::vector<uint32_t>& out) {
          out.clear();
          const float* h = heights.data() + offset[l];
          const float* lo = std::lower_bound(h, h + count[l], t0);
          const float* hi = std::upper_bound(h, h + count[l], t1);
          for (const float* p = lo; p < hi; ++p) out.push_back(vertex_at(l, std::size_t(p - heights.data())));
        };
        collect(a, side_a);
        collect(b, side_b);
        // Zipper between the two vertical sides, counter-clockwise seen from outside:
        // polygon a0 -> b0 -> ... -> b_top -> a_top -> ... -> a0.
        std::size_t i = 0, k = 0;
        const auto h_of = [&](uint32_t idx) { return mesh.vertices[idx][aa]; };
        while (i + 1 < side_a.size() || k + 1 < side_b.size()) {
          const bool advance_b =
              i + 1 >= side_a.size() ||
              (k + 1 < side_b.size() &&
               h_of(side_b[k + 1]) <= h_of(side_a[i + 1]));
          if (advance_b) {
            mesh.triangles.push_back({side_a[i], side_b[k], side_b[k + 1]});
            ++k;
          } else {
            mesh.triangles.push_back({side_a[i], side_b[k], side_a[i + 1]});
            ++i;
          }
        }
      };
      const auto emit_piece = [&](int piece, float t, bool up) {
        uint32_t v[3];
        if (piece < 4) {
          const int k = piece;
          v[0] = vertex(mid_line[(k + 3) & 3], t);
          v[1] = vertex(corner_line[k], t);
          v[2] = vertex(mid_line[k], t);
        } else {
          const int k = piece - 4;
          v[0] = vertex(centre_line, t);
          v[1] = vertex(mid_line[(k + 3) & 3], t);
          v[2] = vertex(mid_line[k], t);
        }
        if (up) {
          mesh.triangles.push_back({v[0], v[1], v[2]});
        } else {
          mesh.triangles.push_back({v[0], v[2], v[1]});
        }
      };

      unsigned config = 0;
      std::size_t pos[4] = {0, 0, 0, 0};
      bool inside[4] = {false, false, false, false};
      float wall_start[8];
      for (const float e : events) {
        unsigned next = config;
        for (int k = 0; k < 4; ++k) {
          const auto& c = cols[k];
          if (pos[k] >= c.size()) continue;
          const float end = inside[k] ? c[pos[k]].hi : c[pos[k]].lo;
          if (end == e) {
            if (inside[k]) ++pos[k];
            inside[k] = !inside[k];
            next ^= 1u << k;
          }
        }
        const uint8_t before = kTables.pieces[config], after = kTables.pieces[next];
        for (unsigned change = before ^ after; change != 0; change &= change - 1) {
          const int p = __builtin_ctz(change);
          emit_piece(p, e, (before >> p) & 1);
        }
        const int8_t* dir0 = kTables.dir[config];
        const int8_t* dir1 = kTables.dir[next];
        for (int q = 0; q < 8; ++q) {
          const int d0 = dir0[q], d1 = dir1[q];
          if (d0 == d1) continue;
          if (d0 != 0) emit_wall(q, d0, wall_start[q], e);
          if (d1 != 0) wall_start[q] = e;
        }
        config = next;
      }
    }
  }

  compute_normals(mesh);
  return mesh;
}

MeshTopology check_topology(const Mesh& mesh) {
  // Directed edge counts: an oriented 2-manifold uses each undirected edge once in each direction.
  std::unordered_map<uint64_t, int> directed;
  directed.reserve(mesh.triangles.size() * 3);
  MeshTopology topo;
  for (const auto& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) ++topo.degenerate_triangles;
    for (int k = 0; k < 3; ++k) ++directed[(uint64_t(t[k]) << 32) | t[(k + 1) % 3]];
  }
  for (const auto& [key, n] : directed) {
    const uint32_t a = uint32_t(key >> 32), b = uint32_t(key);
    if (a > b && directed.contains((uint64_t(b) << 32) | a)) continue;  // counted from the other side
    const auto it = directed.find((uint64_t(b) << 32) | a);
    const int m = it == directed.end() ? 0 : it->second;
    ++topo.edges;
    const int uses = n + m;
    if (uses == 1) ++topo.boundary_edges;
    if (uses > 2) ++topo.non_manifold_edges;
    if (uses == 2 && (n != 1 || m != 1)) ++topo.inconsistent_edges;
  }
  return topo;
}

}  // namespace studio::hull
