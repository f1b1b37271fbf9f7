// Collider traversal: candidate triangle pairs (rvbc per-cluster BVHs with orientation
// culling, kBvh global BVH, kBrute all feature pairs) and feature-pair deduplication (the
// 4-wide cluster traversal: collider_wide.cpp; one feature pair's filters and elementary
// test: collider_narrow.cpp; the orphan sets' tests: collider_orphans.cpp).
//
// Deduplication is exact and needs no marks: a feature pair is tested only from the
// non-culled triangle pair with the smallest (min id, max id) key among all non-culled
// triangle pairs that contain it. `non_culled` is a pointwise predicate and every traversal
// visits a superset of the pairs it accepts, so each feature pair that appears in any
// non-culled pair is tested exactly once (design note: "deduplicate over all non-culled
// pairs, adjacent pairs included").

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "collider_impl.hpp"
#include "plane_filter.hpp"

#if defined(TETSEG_HAVE_OPENMP)
#include <omp.h>
#endif

namespace tetseg {
namespace {

constexpr std::uint8_t kUnc = static_cast<std::uint8_t>(Orientation::kUncertain);

inline std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) noexcept {
  return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
}

}  // namespace

TreeView Collider::Impl::cluster_view(std::uint32_t c) const noexcept {
  const format::Cluster& cl = asset->clusters[c];
  TreeView v;
  v.nodes = asset->bvh_nodes.data() + cl.bvh_offset;
  v.leaf_tris = asset->cluster_triangles.data() + cl.triangle_offset;
  v.box = nbox.data() + cl.bvh_offset;
  v.tri_box = tbox.data();
  v.ntris = topo->cluster_node_ntris.data() + cl.bvh_offset;
  v.nmov = nmov.data() + cl.bvh_offset;
  return v;
}

TreeView Collider::Impl::global_view() const noexcept {
  TreeView v;
  v.nodes = gbvh.nodes.data();
  v.leaf_tris = gbvh.leaf.data();
  v.box = gbvh.box.data();
  v.tri_box = tbox.data();
  v.ntris = gbvh.ntris.data();
  v.nmov = gbvh.mov.data();
  if (opt.mode == ColliderMode::kCone && !rest_mode) v.cone = &cone;
  return v;
}

std::uint32_t Collider::Impl::tree_count() const noexcept {
  if (uses_clusters()) return cluster_count();
  return global_bvh_active() && gbvh.count > 0 ? 1 : 0;
}

TreeView Collider::Impl::tree(std::uint32_t i) const noexcept {
  return uses_clusters() ? cluster_view(i) : global_view();
}

bool Collider::Impl::non_culled(std::uint32_t t1, std::uint32_t t2) const noexcept {
  if (t1 == t2) return false;
  if (!rest_mode && !tmov[t1] && !tmov[t2]) return false;
  if (!boxes_overlap(tbox[t1], tbox[t2], opt.ccd.min_separation)) return false;
  if (orientation_mode()) {
    if (asset->triangle_cluster[t1] == asset->triangle_cluster[t2]) {
      const std::uint8_t c = tcls[t1];
      return c == kUnc || c != tcls[t2];
    }
    // Across clusters: a pair sharing a node is culled (its feature pairs: the seam orphans).
    return !share_node(tris[t1], tris[t2]);
  }
  if (skip_adjacent && !rest_mode && share_node(tris[t1], tris[t2])) return false;
  return true;
}

bool Collider::Impl::seam_culled(std::uint32_t t1, std::uint32_t t2) const noexcept {
  if (!orientation_mode() || asset->triangle_cluster[t1] == asset->triangle_cluster[t2])
    return false;
  if (!tmov[t1] && !tmov[t2]) return false;
  return boxes_overlap(tbox[t1], tbox[t2], opt.ccd.min_separation) &&
         share_node(tris[t1], tris[t2]);
}

bool Collider::Impl::orientation_culled(std::uint32_t t1, std::uint32_t t2) const noexcept {
  if (!orientation_mode() || t1 == t2) return false;
  if (!tmov[t1] && !tmov[t2]) return false;
  if (asset->triangle_cluster[t1] != asset->triangle_cluster[t2]) return false;
  const std::uint8_t c = tcls[t1];
  if (c == kUnc || c != tcls[t2]) return false;
  return boxes_overlap(tbox[t1], tbox[t2], opt.ccd.min_separation);
}

// Tests the feature pairs of triangle t1 of A and t2 of B (t1 != t2 within one body):
// vertex-face both ways and edge-edge, features with four distinct nodes, that no other
// triangle pair claims: `claimed(u, v)` (u of A, v of B) is true when the pair (u, v) tests a
// shared feature pair instead of this one (exact deduplication).
template <typename Claimed>
void test_features(Worker& w, const Collider::Impl& A, std::uint32_t t1, const Collider::Impl& B,
                   std::uint32_t t2, Claimed&& claimed) noexcept {
  const double ms = A.opt.ccd.min_separation;
  // The plane filter first, in every mode: with its static error bound it costs less than the
  // feature boxes it saves (rvbc evaluated it lazily before; docs/benchmarks-history.md, "Static
  // error bounds").
  if (ms <= 0 && plane_separated(w, A, t1, B, t2)) {
    ++w.stats.triangle_pairs_plane_filtered;
    return;
  }
  const bool same = &A == &B;
  const auto& TA = A.tris[t1];
  const auto& TB = B.tris[t2];
  // Vertex-face, both directions.
  for (int dir = 0; dir < 2 && !w.stop; ++dir) {
    const Collider::Impl& PB = dir == 0 ? A : B;  // the vertices' body
    const Collider::Impl& FB = dir == 0 ? B : A;  // the face's body
    const auto& P = dir == 0 ? TA : TB;
    const auto& F = dir == 0 ? TB : TA;
    const std::uint32_t face = dir == 0 ? t2 : t1;
    for (std::uint32_t p : P) {
      if (same && (p == F[0] || p == F[1] || p == F[2])) continue;
      const std::uint32_t ip = PB.topo->surf_index[p];
      // Cheap rejections before the ownership scan (repeated inside, harmless).
      if (!PB.vmoved[ip] && !FB.tmov[face]) continue;
      if (!boxes_overlap(PB.vbox[ip], FB.tbox[face], ms)) continue;
      bool owner = true;
      const auto& vt_offset = PB.topo->vt_offset;
      const auto& vt_list = PB.topo->vt_list;
      for (std::uint32_t k = vt_offset[ip]; k < vt_offset[ip + 1] && owner; ++k)
        if (dir == 0 ? claimed(vt_list[k], face) : claimed(face, vt_list[k])) owner = false;
      if (owner) process_vertex_face(w, PB, p, FB, face);
      if (w.stop) return;
    }
  }
  // Edge-edge. Each edge's swept box is computed once per triangle pair (t2's when a box of
  // t1's edges first meets t2's box) and read by every check below.
  const auto& EA = A.topo->edges;
  const auto& EB = B.topo->edges;
  Box box2[3];
  bool have_box2 = false;
  for (std::uint32_t i = 0; i < 3; ++i) {
    const std::uint32_t e1 = A.topo->tri_edges[t1][i];
    const Box box1 = A.edge_box(e1);
    // tbox[t2] contains the boxes of t2's edges: one check rejects all three.
    if (!boxes_overlap(box1, B.tbox[t2], ms)) continue;
    if (!have_box2) {
      for (std::uint32_t j = 0; j < 3; ++j) box2[j] = B.edge_box(B.topo->tri_edges[t2][j]);
      have_box2 = true;
    }
    const bool moving1 = A.edge_moving(e1);
    for (std::uint32_t j = 0; j < 3; ++j) {
      const std::uint32_t e2 = B.topo->tri_edges[t2][j];
      const auto& E1 = EA[e1];
      const auto& E2 = EB[e2];
      if (same && (E1[0] == E2[0] || E1[0] == E2[1] || E1[1] == E2[0] || E1[1] == E2[1])) continue;
      // edge_boxes_overlap from the boxes at hand.
      if (!moving1 && !B.edge_moving(e2)) continue;
      if (!boxes_overlap(box1, box2[j], ms)) continue;
      bool owner = true;
      const auto& ea_offset = A.topo->et_offset;
      const auto& ea_list = A.topo->et_list;
      const auto& eb_offset = B.topo->et_offset;
      const auto& eb_list = B.topo->et_list;
      for (std::uint32_t k1 = ea_offset[e1]; k1 < ea_offset[e1 + 1] && owner; ++k1) {
        for (std::uint32_t k2 = eb_offset[e2]; k2 < eb_offset[e2 + 1] && owner; ++k2) {
          const std::uint32_t u = ea_list[k1], v = eb_list[k2];
          if ((!same || u != v) && claimed(u, v)) owner = false;
        }
      }
      if (owner) process_edge_edge(w, A, e1, box1, B, e2, box2[j]);
      if (w.stop) return;
    }
  }
}

void Collider::Impl::process_triangle_pair(Worker& w, std::uint32_t t1,
                                           std::uint32_t t2) const noexcept {
  if (!non_culled(t1, t2)) return;
  if (rest_mode) {
    rest_triangle_pair(w, *this, t1, *this, t2);
    return;
  }
  process_non_culled_pair(w, t1, t2);
}

void Collider::Impl::process_non_culled_pair(Worker& w, std::uint32_t t1,
                                             std::uint32_t t2) const noexcept {
  ++w.stats.triangle_pairs;
  const std::uint64_t key = pair_key(t1, t2);
  if (skip_adjacent) {
    // Static ownership (whole-surface modes): the smallest node-disjoint pair holding a feature
    // pair owns it, whatever its boxes (docs/runtime.md, "Adjacent triangle pairs").
    test_features(w, *this, t1, *this, t2, [&](std::uint32_t u, std::uint32_t v) {
      return pair_key(u, v) < key && !share_node(tris[u], tris[v]);
    });
    return;
  }
  test_features(w, *this, t1, *this, t2, [&](std::uint32_t u, std::uint32_t v) {
    return pair_key(u, v) < key && non_culled(u, v);
  });
}

// Contact closure (rvbc): orientation culling is exact for penetration, but when several
// features touch one point at the earliest time (two vertices meeting head on), feature pairs
// in culled triangle pairs can touch at that same time. Re-examines every orientation-culled
// pair of triangles around the nodes of the contacts at `toi` (seeds: the caller's buffer and
// each worker's best), testing each feature pair that no tested triangle pair holds, once.
void Collider::Impl::close_contacts(Worker& w, double toi) noexcept {
  closure_ring.clear();
  auto add_ring = [&](const Contact& c) {
    if (c.toi != toi) return;
    for (std::uint32_t node : c.nodes) {
      const std::uint32_t iv = topo->surf_index[node];
      for (std::uint32_t k = topo->vt_offset[iv]; k < topo->vt_offset[iv + 1]; ++k) {
        const std::uint32_t t = topo->vt_list[k];
        if (!closure_mark[t]) {
          closure_mark[t] = 1;
          closure_ring.push_back(t);
        }
      }
    }
  };
  // The buffer's contacts of this body (a scene's buffer holds other parts' too).
  if (w.sink)
    for (std::size_t i = 0; i < w.sink->written; ++i)
      if (w.sink->out[i].bodies[0] == body_id && w.sink->out[i].bodies[1] == body_id)
        add_ring(w.sink->out[i]);
  for (const Worker& other : workers)
    if (other.has_best) add_ring(other.best);
  const std::size_t ring = closure_ring.size();  // contacts found below add no seeds
  for (std::size_t i = 0; i < ring; ++i) {
    for (std::size_t j = i + 1; j < ring; ++j) {
      const std::uint32_t t1 = closure_ring[i], t2 = closure_ring[j];
      if (!orientation_culled(t1, t2)) continue;
      ++w.stats.closure_pairs;
      const std::uint64_t key = pair_key(t1, t2);
      // Claimed: tested by the traversal (non-culled) or by the seam orphans (a seam-culled
      // holder: docs/runtime.md, "Across clusters"), or earlier in this closure.
      test_features(w, *this, t1, *this, t2, [&](std::uint32_t u, std::uint32_t v) {
        return non_culled(u, v) || seam_culled(u, v) ||
               (pair_key(u, v) < key && closure_mark[u] && closure_mark[v] &&
                orientation_culled(u, v));
      });
    }
  }
  for (std::uint32_t t : closure_ring) closure_mark[t] = 0;
}

// Calls `triangle_pair(t1, t2)` for every triangle pair of leaf a of ta and leaf b of tb
// except those whose t1's swept box misses leaf b's box (margin ms): their triangle boxes are
// disjoint too, which every triangle-pair predicate rejects.
template <typename TrianglePair>
inline void leaf_pair(Worker& w, const TreeView& ta, std::uint32_t a, const TreeView& tb,
                      std::uint32_t b, double ms, TrianglePair&& triangle_pair) noexcept {
  const format::BvhNode& na = ta.nodes[a];
  const format::BvhNode& nb = tb.nodes[b];
  if (na.count == 1 && nb.count == 1) {  // rvbc's cluster leaves
    triangle_pair(ta.leaf_tris[na.first], tb.leaf_tris[nb.first]);
    return;
  }
  for (std::uint32_t i = 0; i < na.count && !w.stop; ++i) {
    const std::uint32_t t1 = ta.leaf_tris[na.first + i];
    if (nb.count > 1 && !boxes_overlap(ta.tri_box[t1], tb.box[b], ms)) continue;
    for (std::uint32_t j = 0; j < nb.count && !w.stop; ++j)
      triangle_pair(t1, tb.leaf_tris[nb.first + j]);
  }
}

// One step of a pair descent: a pair of leaves is processed, otherwise the live child pairs
// are pushed. False when the stack has no room.
template <typename Live, typename TrianglePair>
inline bool descend_pair(Worker& w, const TreeView& ta, const TreeView& tb, const StackItem& it,
                         double ms, Live&& live, TrianglePair&& triangle_pair,
                         std::size_t& top) noexcept {
  if (ta.nodes[it.a].count > 0 && tb.nodes[it.b].count > 0) {
    leaf_pair(w, ta, it.a, tb, it.b, ms, triangle_pair);
    return true;
  }
  if (top + 2 > w.stack.size()) return false;
  push_child_pairs(it, ta, tb, live, w.stack.data(), top);
  return true;
}

// Traverses two different trees (of one body or of two bodies) culled by overlap only. A pair
// is tested (not both still unless `rest`, boxes overlap) before it is pushed, so popped pairs
// are live. False on stack overflow.
template <typename TrianglePair>
bool traverse_tree_pair(Worker& w, const TreeView& ta, const TreeView& tb, double ms, bool rest,
                        TrianglePair&& triangle_pair) noexcept {
  auto live = [&](std::uint32_t a, std::uint32_t b) {
    return (rest || ta.nmov[a] != 0 || tb.nmov[b] != 0) && boxes_overlap(ta.box[a], tb.box[b], ms);
  };
  if (!live(0, 0)) return true;
  std::size_t top = 0;
  w.stack[top++] = {0, 0};
  while (top > 0 && !w.stop) {
    const StackItem it = w.stack[--top];
    ++w.stats.node_pairs_visited;
    if (!descend_pair(w, ta, tb, it, ms, live, triangle_pair, top)) return false;
  }
  return true;
}

bool traverse_bodies(Worker& w, const Collider::Impl& A, const Collider::Impl& B,
                     bool rest) noexcept {
  const double ms = rest ? 0.0 : A.opt.ccd.min_separation;
  // A triangle pair of two bodies is non-culled when not both triangles are still and their
  // swept boxes overlap; a feature pair is tested from the smallest (t of A, t of B) such pair.
  auto live = [&](std::uint32_t u, std::uint32_t v) {
    return (A.tmov[u] || B.tmov[v]) && boxes_overlap(A.tbox[u], B.tbox[v], ms);
  };
  auto triangle_pair = [&](std::uint32_t t1, std::uint32_t t2) {
    if (rest) {
      if (boxes_overlap(A.tbox[t1], B.tbox[t2], 0.0)) rest_triangle_pair(w, A, t1, B, t2);
      return;
    }
    if (!live(t1, t2)) return;
    ++w.stats.triangle_pairs;
    test_features(w, A, t1, B, t2, [&](std::uint32_t u, std::uint32_t v) {
      return (u < t1 || (u == t1 && v < t2)) && live(u, v);
    });
  };
  const std::uint32_t na = A.tree_count(), nb = B.tree_count();
  for (std::uint32_t i = 0; i < na && !w.stop; ++i) {
    const TreeView ta = A.tree(i);
    for (std::uint32_t j = 0; j < nb && !w.stop; ++j) {
      if (!traverse_tree_pair(w, ta, B.tree(j), ms, rest, triangle_pair)) return false;
    }
  }
  return true;
}

// Inlined into both traversal loops (a call per item cost about 10 % of the bvh traversal's
// instructions); used in this file only.
__attribute__((always_inline)) inline bool Collider::Impl::self_item(
    Worker& w, const TreeView& t, const StackItem& it, std::size_t& top) const noexcept {
  const double ms = opt.ccd.min_separation;
  // Pair items are tested (not both still, boxes overlap) before they are pushed, so popped
  // pair items are live.
  auto live_pair = [&](std::uint32_t a, std::uint32_t b) {
    if (!rest_mode && t.nmov[a] == 0 && t.nmov[b] == 0) return false;
    return boxes_overlap(t.box[a], t.box[b], ms);
  };
  auto self_pair = [&](std::uint32_t t1, std::uint32_t t2) { process_triangle_pair(w, t1, t2); };
  if (it.b == kNone) {
    const std::uint32_t n = it.a;
    if (!rest_mode && t.nmov[n] == 0) return true;
    if (t.cone && cone_self_free(*t.cone, t.cone_base + n)) {
      ++w.stats.node_pairs_orientation_culled;
      return true;
    }
    const format::BvhNode& nd = t.nodes[n];
    if (nd.count > 0) {
      for (std::uint32_t i = 0; i < nd.count && !w.stop; ++i)
        for (std::uint32_t j = i + 1; j < nd.count && !w.stop; ++j)
          process_triangle_pair(w, t.leaf_tris[nd.first + i], t.leaf_tris[nd.first + j]);
      return true;
    }
    if (top + 3 > w.stack.size()) return false;
    if (live_pair(nd.first, nd.second)) w.stack[top++] = {nd.first, nd.second};
    w.stack[top++] = {nd.second, kNone};
    w.stack[top++] = {nd.first, kNone};
    return true;
  }
  return descend_pair(w, t, t, it, ms, live_pair, self_pair, top);
}

bool Collider::Impl::traverse_self(Worker& w, const TreeView& t, StackItem first) const noexcept {
  std::size_t top = 0;
  w.stack[top++] = first;
  while (top > 0 && !w.stop) {
    const StackItem it = w.stack[--top];
    ++w.stats.node_pairs_visited;
    if (!self_item(w, t, it, top)) return false;
  }
  return true;
}

bool Collider::Impl::traverse_global_parallel() noexcept {
  Worker& w0 = workers[0];
  const TreeView t = global_view();
  // Breadth first from the root until there are 16 items per worker to balance, within the
  // capacity reserved at construction (an expansion adds at most 4 items): no allocation.
  const std::size_t target = 16 * workers.size();
  frontier.clear();
  frontier.push_back({0, kNone});
  std::size_t head = 0;
  while (head < frontier.size() && frontier.size() - head < target &&
         frontier.size() + 4 <= frontier.capacity() && !w0.stop) {
    const StackItem it = frontier[head++];
    ++w0.stats.node_pairs_visited;
    std::size_t top = 0;
    if (!self_item(w0, t, it, top)) return false;
    for (std::size_t k = 0; k < top; ++k) frontier.push_back(w0.stack[k]);
  }
  if (w0.stop) return true;
  const auto first = static_cast<std::int64_t>(head);
  const auto count = static_cast<std::int64_t>(frontier.size());
  bool overflow = false;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel num_threads(static_cast <int>(workers.size())) reduction(|| : overflow)
  {
    Worker& w = workers[static_cast<std::size_t>(omp_get_thread_num())];
    if (omp_get_thread_num() == 0)
      stats.traversal_threads = static_cast<std::uint32_t>(omp_get_num_threads());
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t i = first; i < count; ++i)
      if (!w.stop && !w.overflow && !traverse_self(w, t, frontier[static_cast<std::size_t>(i)]))
        w.overflow = overflow = true;
  }
#else
  for (std::int64_t i = first; i < count && !w0.stop; ++i)
    if (!traverse_self(w0, t, frontier[static_cast<std::size_t>(i)])) overflow = true;
#endif
  return !overflow;
}

void Collider::Impl::brute_vertex_faces(Worker& w, std::uint32_t i) const noexcept {
  // Vertex i against every triangle not containing it (swept-box overlap checked inside).
  const std::uint32_t p = topo->surf_nodes[i];
  for (std::uint32_t f = 0; f < tri_count && !w.stop; ++f) {
    const auto& F = tris[f];
    if (p == F[0] || p == F[1] || p == F[2]) continue;
    process_vertex_face(w, *this, p, *this, f);
  }
}

void Collider::Impl::brute_edge_edges(Worker& w, std::uint32_t i) const noexcept {
  // Edge i against every later edge with four distinct nodes.
  const std::uint32_t ne = static_cast<std::uint32_t>(topo->edges.size());
  const auto& E1 = topo->edges[i];
  for (std::uint32_t j = i + 1; j < ne && !w.stop; ++j) {
    const auto& E2 = topo->edges[j];
    if (E1[0] == E2[0] || E1[0] == E2[1] || E1[1] == E2[0] || E1[1] == E2[1]) continue;
    process_edge_edge(w, *this, i, *this, j);
  }
}

namespace {

// The items of cluster c1 of `body` (cluster_tasks' work), each to `task` (a WideTask; false
// stops): its own item unless still or of one sign (then counted as skipped in w), then its
// live pairs with the later clusters.
template <typename Task>
bool cluster_items(const Collider::Impl& body, Worker& w, std::uint32_t c1, bool count_skips,
                   Task&& task) noexcept {
  const std::uint32_t nc = body.cluster_count();
  const std::uint32_t r1 = body.topo->wide_root[c1];
  if (r1 == kWideEmpty) return true;
  const bool orient = body.orientation_mode();
  const bool still = !body.rest_mode && body.wmov[r1] == 0;
  if (still || (orient && body.wsign[r1] != 0)) {
    if (count_skips) ++w.stats.clusters_skipped;
  } else if (!task(WideTask{{r1, kNone}, orient, false})) {
    return false;
  }
  for (std::uint32_t c2 = c1 + 1; c2 < nc && !w.stop; ++c2) {
    const std::uint32_t r2 = body.topo->wide_root[c2];
    if (r2 == kWideEmpty) continue;
    if (!body.rest_mode && body.wmov[r1] == 0 && body.wmov[r2] == 0) continue;
    if (!boxes_overlap(body.wbox[r1], body.wbox[r2], body.opt.ccd.min_separation)) continue;
    if (!task(WideTask{{r1, r2}, false, true})) return false;
  }
  return true;
}

}  // namespace

bool Collider::Impl::traverse_clusters_parallel(bool count_skips) noexcept {
  Worker& w0 = workers[0];
  // The items of cluster_tasks, in its order (wide_frontier is sized at construction for all
  // of them and the hand-overs).
  std::size_t queued = 0;
  for (std::uint32_t c = 0; c < cluster_count(); ++c)
    cluster_items(*this, w0, c, count_skips, [&](const WideTask& task) {
      wide_frontier[queued++] = task;
      return true;
    });
  // The workers take items from the queue's end; an idle one waits for a hand-over while
  // others run, and all are done when nothing waits and nothing runs.
  WideQueue queue;
  queue.items = wide_frontier.data();
  queue.capacity = wide_frontier.size();
  queue.count.store(queued, std::memory_order_relaxed);
  bool overflow = false;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel num_threads(static_cast <int>(workers.size())) reduction(|| : overflow)
  {
    Worker& w = workers[static_cast<std::size_t>(omp_get_thread_num())];
    if (omp_get_thread_num() == 0)
      stats.traversal_threads = static_cast<std::uint32_t>(omp_get_num_threads());
    for (;;) {
      WideTask task{};
      bool have = false, done = false;
#pragma omp critical(tetseg_wide_queue)
      {
        const std::size_t count = queue.count.load(std::memory_order_relaxed);
        if (count > 0) {
          task = queue.items[count - 1];
          queue.count.store(count - 1, std::memory_order_relaxed);
          queue.running.fetch_add(1, std::memory_order_relaxed);
          have = true;
        } else if (queue.running.load(std::memory_order_relaxed) == 0) {
          done = true;
        } else {
          queue.hungry.store(true, std::memory_order_relaxed);
        }
      }
      if (done) break;
      if (!have) {
        std::this_thread::yield();
        continue;
      }
      if (!w.stop && !w.overflow && !traverse_wide(w, task.item, task.orient, task.seam, &queue))
        w.overflow = overflow = true;
#pragma omp critical(tetseg_wide_queue)
      queue.running.fetch_sub(1, std::memory_order_relaxed);
    }
  }
#else
  for (std::size_t i = 0; i < queued && !w0.stop; ++i) {
    const WideTask& task = wide_frontier[i];
    if (!traverse_wide(w0, task.item, task.orient, task.seam)) overflow = true;
  }
#endif
  return !overflow;
}

bool Collider::Impl::cluster_tasks(Worker& w, std::uint32_t c1, bool count_skips) const noexcept {
  return cluster_items(*this, w, c1, count_skips, [&](const WideTask& task) {
    return traverse_wide(w, task.item, task.orient, task.seam);
  });
}

bool Collider::Impl::run_query(ContactSink* sink) noexcept {
  const auto t_start = Clock::now();
  for (Worker& w : workers) {
    w.reset();
    w.qkind = qkind;
    w.sink = sink;
  }
  Worker& w0 = workers[0];
  const bool count_skips = !stats.full_traversal && qkind == QueryKind::kFull && !rest_mode;
  // Parallel traversal: OpenMP threads take tasks (an item of the cluster BVHs, handed over
  // below whole clusters when a thread is idle; a subtree of the whole-surface BVH; a brute
  // force vertex or edge), each traversed once; merged in worker order, so counts
  // and the earliest contact equal the serial ones, and a buffer keeps the smallest contacts
  // whoever finds them (ContactSink).
  const bool parallel = workers.size() > 1 && !rest_mode;
  if (parallel && sink) sink->locked = true;
  stats.traversal_threads = 1;
  if (!stats.nothing_moved || rest_mode) {
    const std::uint32_t nc = cluster_count();
    const std::int64_t nv = static_cast<std::int64_t>(topo->surf_nodes.size());
    const std::int64_t ne = static_cast<std::int64_t>(topo->edges.size());
    if (global_bvh_active()) {
      if (tri_count > 0) {
        const bool ok = parallel && frontier.capacity() > 4
                            ? traverse_global_parallel()
                            : traverse_self(w0, global_view(), {0, kNone});
        if (!ok) w0.overflow = true;
      }
      if (skip_adjacent && !rest_mode && !w0.overflow) test_orphans(w0);
    } else if (opt.mode == ColliderMode::kFeatures && !rest_mode) {
      if (!feature_pairs(w0, parallel)) w0.overflow = true;
    } else if (opt.mode == ColliderMode::kBrute && !rest_mode) {
#if defined(TETSEG_HAVE_OPENMP)
      if (parallel) {
#pragma omp parallel num_threads(static_cast <int>(workers.size()))
        {
          Worker& w = workers[static_cast<std::size_t>(omp_get_thread_num())];
          if (omp_get_thread_num() == 0)
            stats.traversal_threads = static_cast<std::uint32_t>(omp_get_num_threads());
#pragma omp for schedule(dynamic, 16)
          for (std::int64_t i = 0; i < nv; ++i)
            if (!w.stop) brute_vertex_faces(w, static_cast<std::uint32_t>(i));
#pragma omp for schedule(dynamic, 16)
          for (std::int64_t i = 0; i < ne; ++i)
            if (!w.stop) brute_edge_edges(w, static_cast<std::uint32_t>(i));
        }
      } else
#endif
      {
        for (std::int64_t i = 0; i < nv && !w0.stop; ++i)
          brute_vertex_faces(w0, static_cast<std::uint32_t>(i));
        for (std::int64_t i = 0; i < ne && !w0.stop; ++i)
          brute_edge_edges(w0, static_cast<std::uint32_t>(i));
      }
    } else {
      if (parallel && !wide_frontier.empty()) {
        if (!traverse_clusters_parallel(count_skips)) w0.overflow = true;
      } else {
        for (std::uint32_t c = 0; c < nc && !w0.stop; ++c) {
          if (!cluster_tasks(w0, c, count_skips)) {
            w0.overflow = true;
            break;
          }
        }
      }
      // After every traversal: the seam orphans that no non-culled pair holds.
      bool done = false;
      for (const Worker& w : workers) done = done || w.stop || w.overflow;
      if (!rest_mode && !done) test_seam_orphans(w0);
    }
  }
  // Contact closure around the earliest contacts (rvbc, full queries).
  if (orientation_mode() && qkind == QueryKind::kFull) {
    bool any_best = false;
    double earliest = 0.0;
    for (const Worker& w : workers) {
      if (w.has_best && (!any_best || w.best.toi < earliest)) earliest = w.best.toi;
      any_best = any_best || w.has_best;
    }
    if (any_best) close_contacts(w0, earliest);
  }
  // Merge in worker order.
  bool overflow = false, hit = false;
  std::size_t found = 0;
  bool has = false;
  Contact first;
  double tests_seconds = 0;
  for (const Worker& w : workers) {
    add_counts(stats, w.stats);
    overflow = overflow || w.overflow;
    hit = hit || w.stop;
    found += w.found;
    tests_seconds += w.tests_seconds;
    keep_earliest(has, first, w.has_best, w.best);
  }
  const double total_ms = ms_since(t_start);
  const double tests_ms = tests_seconds * 1e3;
  stats.tests_ms += tests_ms;
  stats.traversal_ms += std::max(0.0, total_ms - tests_ms);
  if (overflow) return false;
  query_hit = hit;
  if (qkind == QueryKind::kFull && !rest_mode) {
    stats.full_traversal = true;
    cache.set_full(found, has, first);
  }
  return true;
}

}  // namespace tetseg
