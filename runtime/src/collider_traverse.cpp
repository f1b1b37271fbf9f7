// Collider traversal: candidate triangle pairs (rvbc per-cluster BVHs with orientation
// culling, kBvh global BVH, kBrute all feature pairs), feature-pair deduplication, the
// cheap filters and the elementary tests.
//
// Deduplication is exact and needs no marks: a feature pair is tested only from the
// non-culled triangle pair with the smallest (min id, max id) key among all non-culled
// triangle pairs that contain it. `non_culled` is a pointwise predicate and every traversal
// visits a superset of the pairs it accepts, so each feature pair that appears in any
// non-culled pair is tested exactly once (design note: "deduplicate over all non-culled
// pairs, adjacent pairs included").

#include <algorithm>
#include <chrono>

#include "collider_impl.hpp"

namespace tetseg {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::uint8_t kUnc = static_cast<std::uint8_t>(Orientation::kUncertain);

inline std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) noexcept {
  return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
}

inline Vec3d v3(const double* p) noexcept {
  return {p[0], p[1], p[2]};
}

}  // namespace

TreeView Collider::Impl::cluster_view(std::uint32_t c) const noexcept {
  const format::Cluster& cl = asset->clusters[c];
  TreeView v;
  v.nodes = asset->bvh_nodes.data() + cl.bvh_offset;
  v.leaf_tris = asset->cluster_triangles.data() + cl.triangle_offset;
  v.box = nbox.data() + cl.bvh_offset;
  v.ntris = cluster_node_ntris.data() + cl.bvh_offset;
  v.nmov = nmov.data() + cl.bvh_offset;
  if (opt.mode == ColliderMode::kRvbc && !rest_mode) {
    v.nneg = nneg.data() + cl.bvh_offset;
    v.nunc = nunc.data() + cl.bvh_offset;
  }
  return v;
}

TreeView Collider::Impl::global_view() const noexcept {
  TreeView v;
  v.nodes = gnodes.data();
  v.leaf_tris = gleaf.data();
  v.box = gbox.data();
  v.ntris = gntris.data();
  v.nmov = gmov.data();
  return v;
}

bool Collider::Impl::non_culled(std::uint32_t t1, std::uint32_t t2) const noexcept {
  if (t1 == t2) return false;
  if (!rest_mode && !tmov[t1] && !tmov[t2]) return false;
  if (!boxes_overlap(tbox[t1], tbox[t2], opt.ccd.min_separation)) return false;
  if (opt.mode == ColliderMode::kRvbc && !rest_mode &&
      asset->triangle_cluster[t1] == asset->triangle_cluster[t2]) {
    const std::uint8_t c = tcls[t1];
    if (c != kUnc && c == tcls[t2]) return false;
  }
  return true;
}

void Collider::Impl::record(const Contact& c) noexcept {
  ++stats.contacts;
  if (qkind == QueryKind::kAny) {
    stop = true;
    return;
  }
  ++q_found;
  if (!q_has_best || contact_less(c, q_best)) {
    q_best = c;
    q_has_best = true;
  }
  if (out && out_written < out_cap) out[out_written++] = c;
}

void Collider::Impl::process_vertex_face(std::uint32_t p, std::uint32_t face) noexcept {
  const auto& f = asset->triangles[face];
  const std::uint32_t ip = surf_index[p];
  if (!vmoved[ip] && !tmov[face]) return;  // still feature pair: only t = 0 contact possible
  const double ms = opt.ccd.min_separation;
  if (!boxes_overlap(vbox[ip], tbox[face], ms)) return;
  ++stats.feature_pairs;
  if (ms <= 0) {
    // Coplanarity cubic det[b-a, c-a, p-a] with a proven strict sign: never coplanar.
    const Orientation o = classify_orientation(pos0(f[0]), pos0(f[1]), pos0(f[2]), pos0(p),
                                               pos1(f[0]), pos1(f[1]), pos1(f[2]), pos1(p));
    if (o != Orientation::kUncertain) {
      ++stats.feature_pairs_filtered;
      return;
    }
  }
  ++stats.feature_tests;
  Clock::time_point t0;
  if (opt.time_tests) t0 = Clock::now();
  const CcdResult r =
      vertex_face_ccd(v3(pos0(p)), v3(pos0(f[0])), v3(pos0(f[1])), v3(pos0(f[2])), v3(pos1(p)),
                      v3(pos1(f[0])), v3(pos1(f[1])), v3(pos1(f[2])), opt.ccd);
  if (opt.time_tests) tests_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  if (!r.hit()) return;
  Contact c;
  c.kind = ContactKind::kVertexFace;
  c.nodes = {p, f[0], f[1], f[2]};
  c.triangle = face;
  c.at_start = r.outcome == CcdOutcome::kContactAtStart;
  c.toi = c.at_start ? 0.0 : r.toi;
  record(c);
}

bool Collider::Impl::edge_boxes_overlap(std::uint32_t e1, std::uint32_t e2) const noexcept {
  const std::uint32_t ia = surf_index[edges[e1][0]], ib = surf_index[edges[e1][1]];
  const std::uint32_t ic = surf_index[edges[e2][0]], id = surf_index[edges[e2][1]];
  if (!vmoved[ia] && !vmoved[ib] && !vmoved[ic] && !vmoved[id]) return false;
  Box ba = vbox[ia], bc = vbox[ic];
  box_union(ba, vbox[ib]);
  box_union(bc, vbox[id]);
  return boxes_overlap(ba, bc, opt.ccd.min_separation);
}

void Collider::Impl::process_edge_edge(std::uint32_t e1, std::uint32_t e2) noexcept {
  if (e1 > e2) std::swap(e1, e2);
  const std::uint32_t a = edges[e1][0], b = edges[e1][1], c = edges[e2][0], d = edges[e2][1];
  const std::uint32_t ia = surf_index[a], ib = surf_index[b], ic = surf_index[c],
                      id = surf_index[d];
  if (!vmoved[ia] && !vmoved[ib] && !vmoved[ic] && !vmoved[id]) return;
  const double ms = opt.ccd.min_separation;
  if (!edge_boxes_overlap(e1, e2)) return;
  ++stats.feature_pairs;
  if (ms <= 0) {
    // det[b-a, d-c, c-a] = det[b-a, d-a, c-a]: orientation of (a; b, d, c).
    const Orientation o = classify_orientation(pos0(a), pos0(b), pos0(d), pos0(c), pos1(a), pos1(b),
                                               pos1(d), pos1(c));
    if (o != Orientation::kUncertain) {
      ++stats.feature_pairs_filtered;
      return;
    }
  }
  ++stats.feature_tests;
  Clock::time_point t0;
  if (opt.time_tests) t0 = Clock::now();
  const CcdResult r = edge_edge_ccd(v3(pos0(a)), v3(pos0(b)), v3(pos0(c)), v3(pos0(d)), v3(pos1(a)),
                                    v3(pos1(b)), v3(pos1(c)), v3(pos1(d)), opt.ccd);
  if (opt.time_tests) tests_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  if (!r.hit()) return;
  Contact k;
  k.kind = ContactKind::kEdgeEdge;
  k.nodes = {a, b, c, d};  // edges sorted (a<b, c<d) and e1 < e2 in sorted edge order
  k.triangle = 0;
  k.at_start = r.outcome == CcdOutcome::kContactAtStart;
  k.toi = k.at_start ? 0.0 : r.toi;
  record(k);
}

void Collider::Impl::process_triangle_pair(std::uint32_t t1, std::uint32_t t2) noexcept {
  if (!non_culled(t1, t2)) return;
  if (rest_mode) {
    rest_triangle_pair(t1, t2);
    return;
  }
  ++stats.triangle_pairs;
  const std::uint64_t key = pair_key(t1, t2);
  const auto& A = asset->triangles[t1];
  const auto& B = asset->triangles[t2];
  // Vertex-face, both directions.
  for (int dir = 0; dir < 2 && !stop; ++dir) {
    const auto& P = dir == 0 ? A : B;
    const auto& F = dir == 0 ? B : A;
    const std::uint32_t face = dir == 0 ? t2 : t1;
    for (std::uint32_t p : P) {
      if (p == F[0] || p == F[1] || p == F[2]) continue;
      const std::uint32_t ip = surf_index[p];
      // Cheap rejections before the ownership scan (repeated inside, harmless).
      if (!vmoved[ip] && !tmov[face]) continue;
      if (!boxes_overlap(vbox[ip], tbox[face], opt.ccd.min_separation)) continue;
      bool owner = true;
      for (std::uint32_t k = vt_offset[ip]; k < vt_offset[ip + 1] && owner; ++k) {
        const std::uint32_t t = vt_list[k];
        if (pair_key(t, face) < key && non_culled(t, face)) owner = false;
      }
      if (owner) process_vertex_face(p, face);
      if (stop) return;
    }
  }
  // Edge-edge.
  for (std::uint32_t i = 0; i < 3; ++i) {
    const std::uint32_t e1 = tri_edges[t1][i];
    for (std::uint32_t j = 0; j < 3; ++j) {
      const std::uint32_t e2 = tri_edges[t2][j];
      const auto& E1 = edges[e1];
      const auto& E2 = edges[e2];
      if (E1[0] == E2[0] || E1[0] == E2[1] || E1[1] == E2[0] || E1[1] == E2[1]) continue;
      if (!edge_boxes_overlap(e1, e2)) continue;
      bool owner = true;
      for (std::uint32_t k1 = et_offset[e1]; k1 < et_offset[e1 + 1] && owner; ++k1) {
        for (std::uint32_t k2 = et_offset[e2]; k2 < et_offset[e2 + 1] && owner; ++k2) {
          const std::uint32_t u = et_list[k1], w = et_list[k2];
          if (u != w && pair_key(u, w) < key && non_culled(u, w)) owner = false;
        }
      }
      if (owner) process_edge_edge(e1, e2);
      if (stop) return;
    }
  }
}

void Collider::Impl::leaf_pair(const TreeView& ta, std::uint32_t a, const TreeView& tb,
                               std::uint32_t b) noexcept {
  const format::BvhNode& na = ta.nodes[a];
  const format::BvhNode& nb = tb.nodes[b];
  for (std::uint32_t i = 0; i < na.count && !stop; ++i) {
    for (std::uint32_t j = 0; j < nb.count && !stop; ++j) {
      process_triangle_pair(ta.leaf_tris[na.first + i], tb.leaf_tris[nb.first + j]);
    }
  }
}

bool Collider::Impl::traverse_pair(const TreeView& ta, const TreeView& tb,
                                   bool same_cluster) noexcept {
  // Same-tree pairs come from traverse_self, which pushes them; here the roots of two trees.
  std::size_t top = 0;
  stack[top++] = {0, 0};
  while (top > 0 && !stop) {
    const StackItem it = stack[--top];
    ++stats.node_pairs_visited;
    if (!rest_mode && ta.nmov[it.a] == 0 && tb.nmov[it.b] == 0) continue;
    if (!boxes_overlap(ta.box[it.a], tb.box[it.b], opt.ccd.min_separation)) continue;
    const format::BvhNode& na = ta.nodes[it.a];
    const format::BvhNode& nb = tb.nodes[it.b];
    if (na.count > 0 && nb.count > 0) {
      leaf_pair(ta, it.a, tb, it.b);
      continue;
    }
    if (top + 2 > stack.size()) return false;
    const bool split_a = nb.count > 0 || (na.count == 0 && ta.ntris[it.a] >= tb.ntris[it.b]);
    if (split_a) {
      stack[top++] = {na.second, it.b};
      stack[top++] = {na.first, it.b};
    } else {
      stack[top++] = {it.a, nb.second};
      stack[top++] = {it.a, nb.first};
    }
  }
  (void)same_cluster;
  return true;
}

bool Collider::Impl::traverse_self(const TreeView& t) noexcept {
  const bool orient = t.nneg != nullptr;
  auto one_sign = [&](std::uint32_t n) {
    return orient && (t.nunc[n] == 0 && (t.nneg[n] == 0 || t.nneg[n] == t.ntris[n]));
  };
  std::size_t top = 0;
  stack[top++] = {0, kNone};
  while (top > 0 && !stop) {
    const StackItem it = stack[--top];
    ++stats.node_pairs_visited;
    if (it.b == kNone) {
      const std::uint32_t n = it.a;
      if (!rest_mode && t.nmov[n] == 0) continue;
      if (one_sign(n)) {
        ++stats.node_pairs_orientation_culled;
        continue;
      }
      const format::BvhNode& nd = t.nodes[n];
      if (nd.count > 0) {
        for (std::uint32_t i = 0; i < nd.count && !stop; ++i)
          for (std::uint32_t j = i + 1; j < nd.count && !stop; ++j)
            process_triangle_pair(t.leaf_tris[nd.first + i], t.leaf_tris[nd.first + j]);
        continue;
      }
      if (top + 3 > stack.size()) return false;
      stack[top++] = {nd.first, nd.second};
      stack[top++] = {nd.second, kNone};
      stack[top++] = {nd.first, kNone};
      continue;
    }
    if (!rest_mode && t.nmov[it.a] == 0 && t.nmov[it.b] == 0) continue;
    if (!boxes_overlap(t.box[it.a], t.box[it.b], opt.ccd.min_separation)) continue;
    if (orient && t.nunc[it.a] == 0 && t.nunc[it.b] == 0 &&
        ((t.nneg[it.a] == 0 && t.nneg[it.b] == 0) ||
         (t.nneg[it.a] == t.ntris[it.a] && t.nneg[it.b] == t.ntris[it.b]))) {
      ++stats.node_pairs_orientation_culled;
      continue;
    }
    const format::BvhNode& na = t.nodes[it.a];
    const format::BvhNode& nb = t.nodes[it.b];
    if (na.count > 0 && nb.count > 0) {
      leaf_pair(t, it.a, t, it.b);
      continue;
    }
    if (top + 2 > stack.size()) return false;
    const bool split_a = nb.count > 0 || (na.count == 0 && t.ntris[it.a] >= t.ntris[it.b]);
    if (split_a) {
      stack[top++] = {na.second, it.b};
      stack[top++] = {na.first, it.b};
    } else {
      stack[top++] = {it.a, nb.second};
      stack[top++] = {it.a, nb.first};
    }
  }
  return true;
}

void Collider::Impl::run_brute() noexcept {
  // Every vertex against every triangle not containing it, every pair of edges with four
  // distinct nodes; swept-box overlap is checked inside the feature functions.
  const std::uint32_t nv = static_cast<std::uint32_t>(surf_nodes.size());
  for (std::uint32_t i = 0; i < nv && !stop; ++i) {
    const std::uint32_t p = surf_nodes[i];
    for (std::uint32_t f = 0; f < tri_count && !stop; ++f) {
      const auto& F = asset->triangles[f];
      if (p == F[0] || p == F[1] || p == F[2]) continue;
      if (rest_mode) continue;
      process_vertex_face(p, f);
    }
  }
  const std::uint32_t ne = static_cast<std::uint32_t>(edges.size());
  for (std::uint32_t i = 0; i < ne && !stop; ++i) {
    for (std::uint32_t j = i + 1; j < ne && !stop; ++j) {
      const auto& E1 = edges[i];
      const auto& E2 = edges[j];
      if (E1[0] == E2[0] || E1[0] == E2[1] || E1[1] == E2[0] || E1[1] == E2[1]) continue;
      process_edge_edge(i, j);
    }
  }
}

bool Collider::Impl::run_query() noexcept {
  const auto t_start = Clock::now();
  stop = false;
  q_found = 0;
  q_has_best = false;
  out_written = 0;
  tests_seconds = 0;
  bool ok = true;
  if (!stats.nothing_moved || rest_mode) {
    const format::Asset& fa = *asset;
    if (opt.mode == ColliderMode::kBrute && !rest_mode) {
      run_brute();
    } else if (opt.mode == ColliderMode::kBvh && !rest_mode) {
      if (tri_count > 0) ok = traverse_self(global_view());
    } else {
      const std::uint32_t nc = static_cast<std::uint32_t>(fa.clusters.size());
      const bool count_skips = !stats.full_traversal && qkind == QueryKind::kFull;
      for (std::uint32_t c = 0; c < nc && !stop && ok; ++c) {
        const TreeView v = cluster_view(c);
        const bool still = !rest_mode && v.nmov[0] == 0;
        const bool one_sign =
            v.nneg && v.nunc[0] == 0 && (v.nneg[0] == 0 || v.nneg[0] == v.ntris[0]);
        if (still || one_sign) {
          if (count_skips) ++stats.clusters_skipped;
          continue;
        }
        ok = traverse_self(v);
      }
      for (std::uint32_t c1 = 0; c1 < nc && !stop && ok; ++c1) {
        const TreeView v1 = cluster_view(c1);
        for (std::uint32_t c2 = c1 + 1; c2 < nc && !stop && ok; ++c2) {
          const TreeView v2 = cluster_view(c2);
          if (!rest_mode && v1.nmov[0] == 0 && v2.nmov[0] == 0) continue;
          if (!boxes_overlap(v1.box[0], v2.box[0], opt.ccd.min_separation)) continue;
          ok = traverse_pair(v1, v2, false);
        }
      }
    }
  }
  const double total_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_start).count();
  const double tests_ms = tests_seconds * 1e3;
  stats.tests_ms += tests_ms;
  stats.traversal_ms += std::max(0.0, total_ms - tests_ms);
  if (!ok) {
    overflow = true;
    return false;
  }
  if (qkind == QueryKind::kFull && !rest_mode) {
    stats.full_traversal = true;
    full_done = true;
    full_found = q_found;
    has_best = q_has_best;
    best = q_best;
    any_known = true;
    any_value = q_found > 0;
  }
  return true;
}

}  // namespace tetseg
