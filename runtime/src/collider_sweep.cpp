// kSweep broad phase (docs/runtime.md, "Sweep mode"): swept boxes of every surface vertex,
// edge and triangle, rounded outwards to float; vertex-face and edge-edge candidates by sort
// and sweep along the axis where the boxes overlap least; each candidate once (a vertex and a
// face in the bipartite sweep, an edge pair from its earlier edge in the sorted order), pairs
// sharing a node skipped; then the same filters and elementary tests as every mode
// (process_vertex_face / process_edge_edge). Nothing to build per shape: no BVH, no orphan
// sets; the cost is linear in the candidates plus three sorts per step.

#include <algorithm>
#include <cmath>

#include "collider_impl.hpp"

namespace tetseg {
namespace {

using SweepBox = Collider::Impl::SweepBox;

// The largest float <= d (lower bounds) and the smallest float >= d (upper bounds).
inline float float_below(double d) noexcept {
  const float f = static_cast<float>(d);
  return static_cast<double>(f) > d ? std::nextafter(f, -INFINITY) : f;
}
inline float float_above(double d) noexcept {
  const float f = static_cast<float>(d);
  return static_cast<double>(f) < d ? std::nextafter(f, INFINITY) : f;
}

// `b` (inflated by `margin` >= 0, rounded outwards) on the sweep axis `axis` and the other two.
inline SweepBox sweep_box(const Box& b, int axis, double margin, std::uint32_t id) noexcept {
  const int k1 = axis == 0 ? 1 : 0, k2 = axis == 2 ? 1 : 2;
  auto lo = [&](int k) {
    return float_below(margin > 0 ? std::nextafter(b.lo[k] - margin, -INFINITY) : b.lo[k]);
  };
  auto hi = [&](int k) {
    return float_above(margin > 0 ? std::nextafter(b.hi[k] + margin, INFINITY) : b.hi[k]);
  };
  return {lo(axis), hi(axis), lo(k1), hi(k1), lo(k2), hi(k2), id, 0};
}

inline bool cross_overlap(const SweepBox& a, const SweepBox& b) noexcept {
  return !((a.lo1 > b.hi1) | (b.lo1 > a.hi1) | (a.lo2 > b.hi2) | (b.lo2 > a.hi2));
}

inline bool lower_start(const SweepBox& a, const SweepBox& b) noexcept {
  return a.lo < b.lo || (a.lo == b.lo && a.id < b.id);
}

}  // namespace

int Collider::Impl::sweep_axis() const noexcept {
  // The expected overlaps along an axis grow with the boxes' mean extent over the spread of
  // their centres: take the axis where that ratio is smallest (triangles' boxes).
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  double extent[3] = {0, 0, 0};
  for (std::uint32_t t = 0; t < tri_count; ++t) {
    const Box& b = tbox[t];
    for (int k = 0; k < 3; ++k) {
      const double c = b.lo[k] + b.hi[k];
      lo[k] = std::min(lo[k], c);
      hi[k] = std::max(hi[k], c);
      extent[k] += b.hi[k] - b.lo[k];
    }
  }
  int axis = 0;
  double best = INFINITY;
  for (int k = 0; k < 3; ++k) {
    const double spread = hi[k] - lo[k];
    const double ratio = spread > 0 ? extent[k] / spread : INFINITY;
    if (ratio < best) {
      best = ratio;
      axis = k;
    }
  }
  return axis;
}

void Collider::Impl::sweep_features(Worker& w) noexcept {
  const int axis = sweep_axis();
  const double margin = std::max(0.0, opt.ccd.min_separation);
  const std::uint32_t nv = static_cast<std::uint32_t>(topo->surf_nodes.size());
  const std::uint32_t ne = static_cast<std::uint32_t>(topo->edges.size());
  // Still features (every node with x0 == x1 under the still rule) can only meet still
  // features in pairs the rule skips; they stay in the sweep (process_* skip those pairs).
  SweepBox* V = sweep_vertices.data();
  SweepBox* F = sweep_faces.data();
  SweepBox* E = sweep_edges.data();
  for (std::uint32_t i = 0; i < nv; ++i) V[i] = sweep_box(vbox[i], axis, margin, i);
  for (std::uint32_t t = 0; t < tri_count; ++t) F[t] = sweep_box(tbox[t], axis, margin, t);
  for (std::uint32_t e = 0; e < ne; ++e) E[e] = sweep_box(edge_box(e), axis, margin, e);
  std::sort(V, V + nv, lower_start);
  std::sort(F, F + tri_count, lower_start);
  std::sort(E, E + ne, lower_start);

  // Vertex-face, bipartite: a pair overlaps on the axis when v.lo <= f.lo <= v.hi (found
  // from the vertex) or f.lo < v.lo <= f.hi (found from the face): each pair once.
  auto vertex_face = [&](const SweepBox& v, const SweepBox& f) {
    if (!cross_overlap(v, f)) return;
    const std::uint32_t p = topo->surf_nodes[v.id];
    const format::Triangle& tri = tris[f.id];
    if (p == tri[0] || p == tri[1] || p == tri[2]) return;
    process_vertex_face(w, *this, p, *this, f.id);
  };
  for (std::uint32_t i = 0, j = 0; i < nv && !w.stop; ++i) {
    const SweepBox& v = V[i];
    while (j < tri_count && F[j].lo < v.lo) ++j;
    for (std::uint32_t k = j; k < tri_count && F[k].lo <= v.hi; ++k) vertex_face(v, F[k]);
  }
  for (std::uint32_t k = 0, i = 0; k < tri_count && !w.stop; ++k) {
    const SweepBox& f = F[k];
    while (i < nv && V[i].lo <= f.lo) ++i;
    for (std::uint32_t m = i; m < nv && V[m].lo <= f.hi; ++m) vertex_face(V[m], f);
  }

  // Edge-edge: each pair from its earlier edge in the sorted order.
  for (std::uint32_t i = 0; i < ne && !w.stop; ++i) {
    const SweepBox& a = E[i];
    const std::array<std::uint32_t, 2>& ea = topo->edges[a.id];
    for (std::uint32_t j = i + 1; j < ne && E[j].lo <= a.hi; ++j) {
      const SweepBox& b = E[j];
      if (!cross_overlap(a, b)) continue;
      const std::array<std::uint32_t, 2>& eb = topo->edges[b.id];
      if (ea[0] == eb[0] || ea[0] == eb[1] || ea[1] == eb[0] || ea[1] == eb[1]) continue;
      process_edge_edge(w, *this, a.id, *this, b.id);
    }
  }
}

}  // namespace tetseg
