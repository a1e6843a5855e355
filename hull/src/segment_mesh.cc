#include "hull/segment_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <latch>
#include <thread>
#include <unordered_map>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
  const int n =
      int(((config >> 0) & 1) + ((config >> 1) & 1) + ((config >> 2) & 1) + ((config >> 3) & 1));
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
  uint8_t dir_change[16][16];  // bit q: contour direction q differs between two configurations
};
constexpr Tables make_tables() {
  Tables t{};
  for (unsigned c = 0; c < 16; ++c) {
    t.pieces[c] = pieces(c);
    for (int q = 0; q < 8; ++q) t.dir[c][q] = int8_t(contour(t.pieces[c], q));
  }
  for (unsigned a = 0; a < 16; ++a)
    for (unsigned b = 0; b < 16; ++b)
      for (int q = 0; q < 8; ++q)
        if (t.dir[a][q] != t.dir[b][q]) t.dir_change[a][b] |= uint8_t(1u << q);
  return t;
}
constexpr Tables kTables = make_tables();

struct Scratch {
  std::vector<uint32_t> offset, fill, count;
  std::vector<uint8_t> occupied;
  std::vector<float> heights;
  std::vector<int32_t> vertex_of, vertex_of2;  // per slot, the first and second half's vertex
  std::vector<uint32_t> slots, remap;          // the second half's vertices: slot, final index
};

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
  // Area-weighted vertex normals in float (cells are centimetres, the sums stay well scaled).
  const std::size_t n_vertices = mesh.vertices.size();
  mesh.normals.resize(n_vertices);
#if defined(__SSE2__)
  // SSE2 (the x86-64 baseline): one vertex per register, the cross product by two shuffles;
  // the same products and differences as the scalar code, so the same floats.
  struct alignas(16) Lane {
    __m128 v;
  };
  thread_local std::vector<Lane> pos, acc;
  pos.resize(n_vertices);
  acc.assign(n_vertices, Lane{_mm_setzero_ps()});
  for (std::size_t k = 0; k < n_vertices; ++k) {
    const Eigen::Vector3f& x = mesh.vertices[k];
    pos[k].v = _mm_setr_ps(x[0], x[1], x[2], 0.f);
  }
  const Lane* __restrict p = pos.data();
  Lane* __restrict n = acc.data();
  for (const auto& t : mesh.triangles) {
    const __m128 a = p[t[0]].v;
    const __m128 e = _mm_sub_ps(p[t[1]].v, a), f = _mm_sub_ps(p[t[2]].v, a);
    const __m128 e_yzx = _mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 0, 2, 1));
    const __m128 f_yzx = _mm_shuffle_ps(f, f, _MM_SHUFFLE(3, 0, 2, 1));
    const __m128 c_zxy = _mm_sub_ps(_mm_mul_ps(e, f_yzx), _mm_mul_ps(e_yzx, f));
    const __m128 c = _mm_shuffle_ps(c_zxy, c_zxy, _MM_SHUFFLE(3, 0, 2, 1));
    n[t[0]].v = _mm_add_ps(n[t[0]].v, c);
    n[t[1]].v = _mm_add_ps(n[t[1]].v, c);
    n[t[2]].v = _mm_add_ps(n[t[2]].v, c);
  }
  for (std::size_t k = 0; k < n_vertices; ++k) {
    alignas(16) float s[4];
    _mm_store_ps(s, n[k].v);
    const float len = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    mesh.normals[k] =
        len > 0 ? Eigen::Vector3f(s[0] / len, s[1] / len, s[2] / len) : Eigen::Vector3f::Zero();
  }
#else
  std::fill(mesh.normals.begin(), mesh.normals.end(), Eigen::Vector3f::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.vertices[t[0]];
    const Eigen::Vector3f e = mesh.vertices[t[1]] - a, f = mesh.vertices[t[2]] - a;
    const Eigen::Vector3f c(e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2],
                            e[0] * f[1] - e[1] * f[0]);
    for (const uint32_t k : t) mesh.normals[k] += c;
  }
  for (Eigen::Vector3f& x : mesh.normals) {
    const float len = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    x = len > 0 ? Eigen::Vector3f(x / len) : Eigen::Vector3f::Zero();
  }
#endif
}

Mesh segment_marching_cubes(const SegmentSet& set, const MeshOptions& options) {
  const GridSpec& g = set.grid();
  // Work on the bounding rectangle of the non-empty columns (local i, j = global - i0, j0): the
  // cost follows the occupied area, not the box.
  int i0 = g.cells_u, i1 = -1, j0 = g.cells_v, j1 = -1;
  for (int j = 0; j < g.cells_v; ++j) {
    const std::size_t c = set.column_index(0, j);
    const uint32_t* st = set.start().data() + c;
    if (st[0] == st[g.cells_u]) continue;
    j0 = std::min(j0, j), j1 = j;
    for (int i = 0; i < g.cells_u; ++i) {
      if (st[i] != st[i + 1]) {
        i0 = std::min(i0, i);
        i1 = std::max(i1, i);
      }
    }
  }
  if (i1 < 0) return Mesh{};
  const int nu = i1 - i0 + 1, nv = j1 - j0 + 1;
  const Lattice L(nu, nv);
  const auto column = [&](int i, int j) -> std::span<const Interval> {
    if (i < 0 || j < 0 || i >= nu || j >= nv) return {};
    return set.column(i + i0, j + j0);
  };

  // Heights on every lattice line: the end points of the columns whose cells touch the line.
  const std::size_t lines = std::size_t(L.X) * L.Y;
  // Working memory kept per thread between calls (a frame loop meshes every frame): assign()
  // reuses the capacity, so steady-state frames allocate only the output.
  thread_local Scratch scratch;
  std::vector<uint32_t>& offset = scratch.offset;
  offset.assign(lines + 1, 0);
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
  std::vector<uint8_t>& occupied = scratch.occupied;
  occupied.assign(ow * (std::size_t(nv) + 2), 0);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const uint32_t n = uint32_t(2 * column(i, j).size());
      if (!n) continue;
      occupied[std::size_t(i + 1) + std::size_t(j + 1) * ow] = 1;
      for_lines_of_column(i, j, [&](std::size_t l) { offset[l + 1] += n; });
    }
  for (std::size_t l = 0; l < lines; ++l) offset[l + 1] += offset[l];
  std::vector<float>& heights = scratch.heights;
  heights.resize(offset.back());
  std::vector<uint32_t>& fill = scratch.fill;
  fill.assign(offset.begin(), offset.end() - 1);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const auto col = column(i, j);
      if (col.empty()) continue;
      for_lines_of_column(i, j, [&](std::size_t l) {
        for (const Interval& iv : col) {
          heights[fill[l]++] = iv.lo;
          heights[fill[l]++] = iv.hi;
        }
      });
    }
  std::vector<uint32_t>& count = scratch.count;
  count.assign(lines, 0);
  // Each line's heights sorted and deduplicated (lines are independent).
  const auto sort_lines = [&](std::size_t first, std::size_t last) {
    for (std::size_t l = first; l < last; ++l) {
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
  };
  const double du = g.du(), dv = g.dv();
  const int ua = g.u(), va = g.v(), aa = g.a();

  // Per cell: lattice lines of corners, mid-edges and centre (doubled offsets from c0).
  static constexpr int kCorner[4][2] = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  static constexpr int kMid[4][2] = {{1, 0}, {2, 1}, {1, 2}, {0, 1}};
  // The cells of rows [cj_begin, cj_end) into `mesh`; vertex_of[slot] is the vertex made for
  // heights[slot] (-1: none yet); `slots`, when given, receives the slot of every new vertex.
  const auto mesh_rows = [&](int cj_begin, int cj_end, Mesh& mesh, int32_t* vertex_of,
                             std::vector<uint32_t>* slots) {
    // The vertex at heights[slot] of line l (created on first use).
    const auto vertex_at = [&](std::size_t l, std::size_t slot) -> uint32_t {
      int32_t& id = vertex_of[slot];
      if (id < 0) {
        const float t = heights[slot];
        id = int32_t(mesh.vertices.size());
        const int x2 = int(l % std::size_t(L.X)), y2 = int(l / std::size_t(L.X));
        Eigen::Vector3d p;
        p[ua] = g.box_min[ua] + (x2 * 0.5 - 0.5 + i0) * du;
        p[va] = g.box_min[va] + (y2 * 0.5 - 0.5 + j0) * dv;
        p[aa] = t;
        mesh.vertices.push_back(p.cast<float>());
        if (slots) slots->push_back(uint32_t(slot));
      }
      return uint32_t(id);
    };
    for (int cj = cj_begin; cj < cj_end; ++cj) {
      const uint8_t* occ0 = occupied.data() + std::size_t(cj + 1) * ow;
      const uint8_t* occ1 = occ0 + ow;
      for (int ci = -1; ci < nu; ++ci) {
        if (!(occ0[ci + 1] | occ0[ci + 2] | occ1[ci + 1] | occ1[ci + 2])) continue;
        const std::span<const Interval> cols[4] = {column(ci, cj), column(ci + 1, cj),
                                                   column(ci + 1, cj + 1), column(ci, cj + 1)};
        if (cols[0].empty() && cols[1].empty() && cols[2].empty() && cols[3].empty()) continue;
        const int x0 = 2 * ci + 2, y0 = 2 * cj + 2;
        // The cell's nine lattice lines: corners 0-3, mid-edges 4-7 (m_k = 4 + k), centre 8.
        std::size_t line[9];
        for (int k = 0; k < 4; ++k) {
          line[k] = L.line(x0 + kCorner[k][0], y0 + kCorner[k][1]);
          line[4 + k] = L.line(x0 + kMid[k][0], y0 + kMid[k][1]);
        }
        line[8] = L.line(x0 + 1, y0 + 1);
        // The centre line holds exactly the end points of the cell's four columns: the events.
        const float* events = heights.data() + offset[line[8]];
        const uint32_t n_events = count[line[8]];
        // Per line a cursor into its sorted heights; events come in increasing order, so every
        // lookup at the current event moves a cursor forward (no search). Mid-edge and centre
        // lines hold every event of the cell, a corner line the end points of its column.
        std::size_t cursor[9], end[9];
        for (int k = 0; k < 9; ++k)
          cursor[k] = offset[line[k]], end[k] = cursor[k] + count[line[k]];
        const auto slot_at = [&](int k, float t) -> std::size_t {
          std::size_t& c = cursor[k];
          while (c < end[k] && heights[c] < t) ++c;
          return c;
        };
        // Internal piece edges q = 0..3: T_q | D_q, line pair (m_q, m_{q-1});
        // q = 4..7: D_{q-4} | D_{q-3}, line pair (m_{q-4}, o); first line when the first piece
        // (T_q or D_{q-4}) is inside.
        const auto edge_line = [](int q, int side) -> int {
          if (q < 4) return side == 0 ? 4 + q : 4 + ((q + 3) & 3);
          return side == 0 ? 4 + (q - 4) : 8;
        };
        std::size_t wall_start[8][2];
        const auto emit_wall = [&](int q, int dir, float e) {
          const int la = edge_line(q, dir > 0 ? 0 : 1), lb = edge_line(q, dir > 0 ? 1 : 0);
          const std::size_t sa = wall_start[q][dir > 0 ? 0 : 1],
                            sb = wall_start[q][dir > 0 ? 1 : 0];
          const std::size_t ea = slot_at(la, e), eb = slot_at(lb, e);
          // Zipper between the two vertical sides (every height of each line in [start, e]),
          // counter-clockwise seen from outside: polygon a0 -> b0 -> ... -> b_top -> a_top -> a0.
          const std::size_t la_line = line[la], lb_line = line[lb];
          std::size_t i = sa, k = sb;
          uint32_t va = vertex_at(la_line, i), vb = vertex_at(lb_line, k);
          while (i < ea || k < eb) {
            if (i >= ea || (k < eb && heights[k + 1] <= heights[i + 1])) {
              const uint32_t vn = vertex_at(lb_line, ++k);
              mesh.triangles.push_back({va, vb, vn});
              vb = vn;
            } else {
              const uint32_t vn = vertex_at(la_line, ++i);
              mesh.triangles.push_back({va, vb, vn});
              va = vn;
            }
          }
        };
        const auto emit_piece = [&](int piece, float t, bool up) {
          uint32_t v[3];
          if (piece < 4) {
            const int k = piece;
            v[0] = vertex_at(line[4 + ((k + 3) & 3)], slot_at(4 + ((k + 3) & 3), t));
            v[1] = vertex_at(line[k], slot_at(k, t));
            v[2] = vertex_at(line[4 + k], slot_at(4 + k, t));
          } else {
            const int k = piece - 4;
            v[0] = vertex_at(line[8], slot_at(8, t));
            v[1] = vertex_at(line[4 + ((k + 3) & 3)], slot_at(4 + ((k + 3) & 3), t));
            v[2] = vertex_at(line[4 + k], slot_at(4 + k, t));
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
        for (uint32_t ev = 0; ev < n_events; ++ev) {
          const float e = events[ev];
          unsigned next = config;
          for (int k = 0; k < 4; ++k) {
            const auto& c = cols[k];
            if (pos[k] >= c.size()) continue;
            const float edge = inside[k] ? c[pos[k]].hi : c[pos[k]].lo;
            if (edge == e) {
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
          for (unsigned walls = kTables.dir_change[config][next]; walls != 0; walls &= walls - 1) {
            const int q = __builtin_ctz(walls);
            const int d0 = dir0[q], d1 = dir1[q];
            if (d0 != 0) emit_wall(q, d0, e);
            if (d1 != 0) {
              wall_start[q][0] = slot_at(edge_line(q, 0), e);
              wall_start[q][1] = slot_at(edge_line(q, 1), e);
            }
          }
          config = next;
        }
      }
    }
  };

  std::vector<int32_t>& vertex_of = scratch.vertex_of;
  Mesh mesh;
  mesh.vertices.reserve(heights.size());  // untouched reserve costs address space only
  mesh.triangles.reserve(2 * heights.size());
  // Rows of cells -1 .. nv-1. Two threads: split where half the occupied columns are behind;
  // each thread sorts the lines its rows need and meshes its rows. Lattice row 2 * split + 2 is
  // the one both halves touch: the first sorts it, the second waits for that. The second half's
  // vertices on it are matched to the first half's by slot, the rest appended in the second
  // half's order of first use: the order one thread makes them in, so the mesh is the same for
  // any thread count.
  int split = nv;
  if (options.threads >= 2 && nv >= 16) {
    std::size_t total = 0;
    for (uint8_t o : occupied) total += o;
    std::size_t behind = 0;
    for (int j = 0; j < nv && split == nv; ++j) {
      for (int i = 0; i < nu; ++i) behind += occupied[std::size_t(i + 1) + std::size_t(j + 1) * ow];
      if (2 * behind >= total) split = j + 1;
    }
    if (split >= nv - 1) split = nv;
  }
  if (split == nv) {
    sort_lines(0, lines);
    vertex_of.assign(heights.size(), -1);
    mesh_rows(-1, nv, mesh, vertex_of.data(), nullptr);
  } else {
    const std::size_t shared_end = std::size_t(2 * split + 3) * std::size_t(L.X);  // y2 <= 2s+2
    std::vector<int32_t>& vertex_of2 = scratch.vertex_of2;
    Mesh upper;
    std::vector<uint32_t>& slots = scratch.slots;
    slots.clear();
    {
      std::latch shared_sorted(1);
      std::jthread worker([&] {
        sort_lines(shared_end, lines);
        vertex_of2.assign(heights.size(), -1);
        shared_sorted.wait();
        mesh_rows(split, nv, upper, vertex_of2.data(), &slots);
      });
      sort_lines(0, shared_end);
      shared_sorted.count_down();
      vertex_of.assign(heights.size(), -1);
      mesh_rows(-1, split, mesh, vertex_of.data(), nullptr);
    }
    std::vector<uint32_t>& remap = scratch.remap;
    remap.resize(upper.vertices.size());
    for (std::size_t k = 0; k < upper.vertices.size(); ++k) {
      const int32_t shared = vertex_of[slots[k]];
      if (shared >= 0) {
        remap[k] = uint32_t(shared);
      } else {
        remap[k] = uint32_t(mesh.vertices.size());
        mesh.vertices.push_back(upper.vertices[k]);
      }
    }
    const std::size_t first = mesh.triangles.size();
    mesh.triangles.insert(mesh.triangles.end(), upper.triangles.begin(), upper.triangles.end());
    for (std::size_t t = first; t < mesh.triangles.size(); ++t)
      for (uint32_t& v : mesh.triangles[t]) v = remap[v];
  }

  if (options.normals) compute_normals(mesh);
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
    if (a > b && directed.contains((uint64_t(b) << 32) | a))
      continue;  // counted from the other side
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
