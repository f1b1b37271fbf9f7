#pragma once
/// \file
/// The brute-force truth over a whole scene, sharing nothing with the runtime's narrow phase
/// (its own feature enumeration; none of the collider's still-pair code, swept feature boxes,
/// coplanarity or plane filters): every feature pair with four distinct nodes (vertex against
/// triangle, edge against edge, within a body with self-collision on and across every pair of
/// bodies) through the elementary tests of ccd.hpp only. Pairs whose four nodes are all still
/// are skipped (the documented rule of Collider::step and Scene) unless `include_still` (the
/// runtime's `include_still_pairs`); a plain sort-and-sweep on
/// swept feature boxes (exact box overlap, nothing else) keeps it affordable on large scenes.
/// Shared by the runtime tests, `tetseg-bench table`, `check` and `scene`. The elementary
/// tests themselves are held to exact rational truth by exact_ccd.hpp (tests only).
/// Also the closed and open boxes used as still obstacles.

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "tetseg/runtime/ccd.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

namespace tetseg::test {

/// One body of the oracle: triangles over local node ids and its positions at both ends of
/// the step (node_count * 3 doubles each; x1 == x0 for a still body).
struct OracleBody {
  const std::array<std::uint32_t, 3>* tris = nullptr;
  std::size_t triangle_count = 0;
  const double* x0 = nullptr;
  const double* x1 = nullptr;
  bool self = true;  ///< test the body against itself
};

/// Calls `vertex_face(vertex_body, p, face_body, triangle_id, face_nodes)` and
/// `edge_edge(body_ab, a, b, body_cd, c, d)` once for every feature pair of the step that the
/// oracle tests: four distinct nodes, self pairs only in bodies with `self`, not all four nodes
/// still (unless `include_still`), swept boxes overlapping (exact comparisons). Edges are named as
/// the runtime names them (a < b, c < d, (body, a, b) <= (body, c, d)).
template <class VertexFace, class EdgeEdge>
void for_each_feature_pair(const std::vector<OracleBody>& bodies, VertexFace&& vertex_face,
                           EdgeEdge&& edge_edge, bool include_still = false) {
  enum Kind : std::uint8_t { kVertex, kEdge, kTriangle };
  struct Item {
    double lo[3], hi[3];
    std::uint32_t body;
    Kind kind;
    std::uint32_t id;  // triangle id (kTriangle), else unused
    std::array<std::uint32_t, 3> nodes;
    bool moving;
  };
  std::vector<Item> items;
  auto add_item = [&](std::uint32_t b, Kind kind, std::uint32_t id,
                      std::array<std::uint32_t, 3> nodes, int count) {
    Item it{};
    it.body = b;
    it.kind = kind;
    it.id = id;
    it.nodes = nodes;
    it.moving = false;
    for (int k = 0; k < 3; ++k) {
      it.lo[k] = INFINITY;
      it.hi[k] = -INFINITY;
    }
    for (int c = 0; c < count; ++c) {
      const double* p0 = bodies[b].x0 + std::size_t(nodes[c]) * 3;
      const double* p1 = bodies[b].x1 + std::size_t(nodes[c]) * 3;
      if (!(p0[0] == p1[0] && p0[1] == p1[1] && p0[2] == p1[2])) it.moving = true;
      for (int k = 0; k < 3; ++k) {
        it.lo[k] = std::min({it.lo[k], p0[k], p1[k]});
        it.hi[k] = std::max({it.hi[k], p0[k], p1[k]});
      }
    }
    items.push_back(it);
  };
  for (std::uint32_t b = 0; b < bodies.size(); ++b) {
    std::vector<std::uint32_t> verts;
    std::vector<std::array<std::uint32_t, 2>> edges;
    for (std::size_t t = 0; t < bodies[b].triangle_count; ++t) {
      const auto& T = bodies[b].tris[t];
      add_item(b, kTriangle, static_cast<std::uint32_t>(t), T, 3);
      for (int k = 0; k < 3; ++k) {
        verts.push_back(T[k]);
        edges.push_back({std::min(T[k], T[(k + 1) % 3]), std::max(T[k], T[(k + 1) % 3])});
      }
    }
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (std::uint32_t v : verts) add_item(b, kVertex, 0, {v, v, v}, 1);
    for (const auto& e : edges) add_item(b, kEdge, 0, {e[0], e[1], e[1]}, 2);
  }
  std::sort(items.begin(), items.end(),
            [](const Item& a, const Item& b) { return a.lo[0] < b.lo[0]; });

  auto vf = [&](const Item& v, const Item& f) {
    const std::uint32_t p = v.nodes[0];
    const auto& F = f.nodes;
    if (v.body == f.body && (p == F[0] || p == F[1] || p == F[2])) return;
    vertex_face(v.body, p, f.body, f.id, F);
  };
  auto ee = [&](const Item* e, const Item* g) {
    if (e->body > g->body ||
        (e->body == g->body && std::array<std::uint32_t, 2>{e->nodes[0], e->nodes[1]} >
                                   std::array<std::uint32_t, 2>{g->nodes[0], g->nodes[1]}))
      std::swap(e, g);
    const std::uint32_t a = e->nodes[0], b = e->nodes[1], c = g->nodes[0], d = g->nodes[1];
    if (e->body == g->body && (a == c || a == d || b == c || b == d)) return;
    edge_edge(e->body, a, b, g->body, c, d);
  };
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Item& A = items[i];
    for (std::size_t j = i + 1; j < items.size() && items[j].lo[0] <= A.hi[0]; ++j) {
      const Item& B = items[j];
      if (!include_still && !A.moving && !B.moving) continue;  // all four nodes still
      if (A.body == B.body && !bodies[A.body].self) continue;
      if (A.lo[1] > B.hi[1] || B.lo[1] > A.hi[1] || A.lo[2] > B.hi[2] || B.lo[2] > A.hi[2])
        continue;
      if (A.kind == kVertex && B.kind == kTriangle) vf(A, B);
      if (A.kind == kTriangle && B.kind == kVertex) vf(B, A);
      if (A.kind == kEdge && B.kind == kEdge) ee(&A, &B);
    }
  }
}

/// Position of node `n` of `body` at the start (end = false) or the end of the step.
inline Vec3d oracle_point(const OracleBody& body, std::uint32_t n, bool end) {
  const double* x = (end ? body.x1 : body.x0) + std::size_t(n) * 3;
  return Vec3d{x[0], x[1], x[2]};
}

/// The answer of an elementary test for one feature pair, as the oracles record it.
struct OracleAnswer {
  bool hit = false;
  bool at_start = false;  ///< touching at t = 0 (toi 0)
  double toi = 1.0;
};

/// All contacts of the step, every feature pair of for_each_feature_pair decided by
/// `vertex_face(p0, a0, b0, c0, p1, a1, b1, c1)` or `edge_edge(a0, b0, c0, d0, a1, b1, c1, d1)`
/// (each returning an OracleAnswer), sorted by `contact_less`, named as the runtime names them.
template <class VertexFaceTest, class EdgeEdgeTest>
std::vector<Contact> scene_contacts(const std::vector<OracleBody>& bodies,
                                    VertexFaceTest&& vertex_face, EdgeEdgeTest&& edge_edge,
                                    bool include_still = false) {
  std::vector<Contact> out;
  auto add = [&](ContactKind kind, std::uint32_t ba, std::uint32_t bb,
                 std::array<std::uint32_t, 4> nodes, std::uint32_t tri, const OracleAnswer& r) {
    if (!r.hit) return;
    Contact c;
    c.kind = kind;
    c.bodies = {ba, bb};
    c.nodes = nodes;
    c.triangle = tri;
    c.at_start = r.at_start;
    c.toi = r.at_start ? 0.0 : r.toi;
    out.push_back(c);
  };
  auto at = [&](std::uint32_t b, std::uint32_t n, bool end) {
    return oracle_point(bodies[b], n, end);
  };
  for_each_feature_pair(
      bodies,
      [&](std::uint32_t vb, std::uint32_t p, std::uint32_t fb, std::uint32_t tri,
          const std::array<std::uint32_t, 3>& F) {
        add(ContactKind::kVertexFace, vb, fb, {p, F[0], F[1], F[2]}, tri,
            vertex_face(at(vb, p, false), at(fb, F[0], false), at(fb, F[1], false),
                        at(fb, F[2], false), at(vb, p, true), at(fb, F[0], true),
                        at(fb, F[1], true), at(fb, F[2], true)));
      },
      [&](std::uint32_t eb, std::uint32_t a, std::uint32_t b, std::uint32_t gb, std::uint32_t c,
          std::uint32_t d) {
        add(ContactKind::kEdgeEdge, eb, gb, {a, b, c, d}, 0,
            edge_edge(at(eb, a, false), at(eb, b, false), at(gb, c, false), at(gb, d, false),
                      at(eb, a, true), at(eb, b, true), at(gb, c, true), at(gb, d, true)));
      },
      include_still);
  std::sort(out.begin(), out.end(), contact_less);
  return out;
}

/// All contacts of the step through the elementary tests of ccd.hpp, sorted by
/// `contact_less`, named as the runtime names them.
inline std::vector<Contact> scene_brute_contacts(const std::vector<OracleBody>& bodies,
                                                 bool include_still = false) {
  auto answer = [](const CcdResult& r) {
    return OracleAnswer{r.hit(), r.outcome == CcdOutcome::kContactAtStart, r.toi};
  };
  return scene_contacts(
      bodies,
      [&](const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& p1,
          const Vec3d& a1, const Vec3d& b1,
          const Vec3d& c1) { return answer(vertex_face_ccd(p0, a0, b0, c0, p1, a1, b1, c1)); },
      [&](const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0, const Vec3d& a1,
          const Vec3d& b1, const Vec3d& c1,
          const Vec3d& d1) { return answer(edge_edge_ccd(a0, b0, c0, d0, a1, b1, c1, d1)); },
      include_still);
}

/// Closed box [lo, hi] with n x n quads (two triangles each) per face, wound outward; with
/// `open_side` in 0..2 the face at hi along that axis is left out (a bin open at the top).
inline Surface box_surface(const P3& lo, const P3& hi, int n, int open_side = -1) {
  Surface s;
  std::map<std::array<int, 3>, std::uint32_t> index;
  auto vertex = [&](std::array<int, 3> g) {
    auto it = index.find(g);
    if (it != index.end()) return it->second;
    P3 p;
    for (int k = 0; k < 3; ++k) p[k] = lo[k] + (hi[k] - lo[k]) * g[k] / n;
    s.verts.push_back(p);
    return index[g] = static_cast<std::uint32_t>(s.verts.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side <= n; side += n) {
      if (axis == open_side && side == n) continue;
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          std::array<std::uint32_t, 4> q;
          const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            std::array<int, 3> g{};
            g[axis] = side;
            g[u] = i + di[c];
            g[v] = j + dj[c];
            q[c] = vertex(g);
          }
          if (side == n) {
            s.tris.push_back({q[0], q[1], q[2]});
            s.tris.push_back({q[0], q[2], q[3]});
          } else {
            s.tris.push_back({q[0], q[2], q[1]});
            s.tris.push_back({q[0], q[3], q[2]});
          }
        }
      }
    }
  }
  return s;
}

}  // namespace tetseg::test
