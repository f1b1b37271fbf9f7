// Collider traversal: candidate triangle pairs (rvbc per-cluster BVHs with orientation
// culling, kBvh global BVH, kBrute all feature pairs), feature-pair deduplication, the
// cheap filters and the elementary tests (the 4-wide cluster traversal: collider_wide.cpp).
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

void Worker::record(const Contact& c) noexcept {
  ++stats.contacts;
  if (qkind == QueryKind::kAny) {
    stop = true;
    return;
  }
  ++found;
  if (!has_best || contact_less(c, best)) {
    best = c;
    has_best = true;
  }
  if (out && out_written < out_cap) out[out_written++] = c;
}

// ------------------------------------------------- the one feature-pair path
// Feature pairs of a triangle of body A and a triangle of body B (A == B for self-collision):
// swept-box checks, the coplanarity filter, the elementary test, the contact. Options (ccd,
// timing) are A's; a scene gives all its bodies the same.

namespace {

// The plane of triangle t of `body` for this step (FacePlaneStatic::of its nodes).
FacePlaneStatic plane_of(const Collider::Impl& body, std::uint32_t t) noexcept {
  const auto& f = body.tris[t];
  return FacePlaneStatic::of(body.pos0(f[0]), body.pos0(f[1]), body.pos0(f[2]), body.pos1(f[0]),
                             body.pos1(f[1]), body.pos1(f[2]));
}

// Plane of triangle t of `body` for this step: from w's per-step cache when w caches that
// body (its own collider's, or any body's for a scene worker; computed there at first use),
// else null (FaceSides computes it). Same values either way (the same operations in the same
// order).
inline const FacePlaneStatic* face_plane(Worker& w, const Collider::Impl& body,
                                         std::uint32_t t) noexcept {
  std::size_t i = t;
  if (w.plane_owner != &body) {
    if (body.body_id >= w.plane_base.size()) return nullptr;
    i += w.plane_base[body.body_id];
  }
  if (w.plane_step[i] != body.step_serial) {
    w.plane[i] = plane_of(body, t);
    w.plane_step[i] = body.step_serial;
  }
  return &w.plane[i];
}

// StaticErr::of the extents of the union of boxes a and b (box_union's values: the smaller
// lower bound, the larger upper bound, per axis).
inline orientation_detail::StaticErr union_static_err(const Box& a, const Box& b) noexcept {
#if defined(__SSE2__)
  // min(b, a) and max(b, a) lane by lane pick as box_union's comparisons do.
  const __m128d lo = _mm_min_pd(_mm_loadu_pd(b.lo), _mm_loadu_pd(a.lo));
  const __m128d hi = _mm_max_pd(_mm_loadu_pd(b.hi), _mm_loadu_pd(a.hi));
  double xy[2];
  _mm_storeu_pd(xy, _mm_sub_pd(hi, lo));
  const double z_lo = b.lo[2] < a.lo[2] ? b.lo[2] : a.lo[2];
  const double z_hi = b.hi[2] > a.hi[2] ? b.hi[2] : a.hi[2];
  const double extent[3] = {xy[0], xy[1], z_hi - z_lo};
#else
  Box u = a;
  box_union(u, b);
  const double extent[3] = {u.hi[0] - u.lo[0], u.hi[1] - u.lo[1], u.hi[2] - u.lo[2]};
#endif
  return orientation_detail::StaticErr::of(extent);
}

// The `count` nodes of body O stay strictly on one side of the plane of triangle t of body T
// for the whole step, each side proven by the error-bounded orientation cubic. `box` holds the
// nodes at both ends of the step (with t's swept box: the static error bound).
bool nodes_off_plane(Worker& w, const Collider::Impl& T, std::uint32_t t, const Collider::Impl& O,
                     const std::uint32_t* nodes, int count, const Box& box) noexcept {
  // A node of the triangle itself has a zero cubic, never a proven side: the answer is false
  // (as the cubics would give it, found without them).
  const auto& tn = T.tris[t];
  if (&T == &O)
    for (int i = 0; i < count; ++i)
      if (nodes[i] == tn[0] || nodes[i] == tn[1] || nodes[i] == tn[2]) return false;
  const orientation_detail::StaticErr err = union_static_err(T.tbox[t], box);
  const MovingTriangle face{tn, T.x0, T.x1, face_plane(w, T, t)};
  FaceSides sides(face, &err);
  Orientation side = Orientation::kUncertain;
  for (int i = 0; i < count; ++i) {
    const Orientation o = sides.of(O.pos0(nodes[i]), O.pos1(nodes[i]));
    if (o == Orientation::kUncertain || (i > 0 && o != side)) return false;
    side = o;
  }
  return true;
}

// Edge-pair plane filter (exact contact only): both nodes of edge e2 of B stay strictly on one
// side of the plane of a triangle of A around edge e1. e1 lies in that plane at every t of
// the step, so the edges never touch.
bool edge_off_face_planes(Worker& w, const Collider::Impl& A, std::uint32_t e1,
                          const Collider::Impl& B, std::uint32_t e2) noexcept {
  const auto& et_offset = A.topo->et_offset;
  for (std::uint32_t k = et_offset[e1]; k < et_offset[e1 + 1]; ++k)
    if (nodes_off_plane(w, A, A.topo->et_list[k], B, B.topo->edges[e2].data(), 2, B.edge_box(e2)))
      return true;
  return false;
}

// Vertex-face plane filter (exact contact only): the three nodes of face `face` of F stay
// strictly on one side of the plane of a triangle of P around node p. p lies in that plane at
// every t of the step, so it never touches the face.
bool face_off_vertex_planes(Worker& w, const Collider::Impl& P, std::uint32_t p,
                            const Collider::Impl& F, std::uint32_t face) noexcept {
  const std::uint32_t ip = P.topo->surf_index[p];
  const auto& vt_offset = P.topo->vt_offset;
  for (std::uint32_t k = vt_offset[ip]; k < vt_offset[ip + 1]; ++k)
    if (nodes_off_plane(w, P, P.topo->vt_list[k], F, F.tris[face].data(), 3, F.tbox[face]))
      return true;
  return false;
}

}  // namespace

void process_vertex_face(Worker& w, const Collider::Impl& P, std::uint32_t p,
                         const Collider::Impl& F, std::uint32_t face) noexcept {
  const auto& f = F.tris[face];
  const std::uint32_t ip = P.topo->surf_index[p];
  if (!P.vmoved[ip] && !F.tmov[face]) return;  // still feature pair: only t = 0 contact possible
  const ColliderOptions& opt = P.opt;
  const double ms = opt.ccd.min_separation;
  if (!boxes_overlap(P.vbox[ip], F.tbox[face], ms)) return;
  ++w.stats.feature_pairs;
  if (ms <= 0) {
    // Coplanarity cubic det[b-a, c-a, p-a] with a proven strict sign: never coplanar. Its
    // points lie in the union of the vertex's and the face's swept boxes (static bound).
    const Orientation o = orientation_of(F.pos0(f[0]), F.pos0(f[1]), F.pos0(f[2]), P.pos0(p),
                                         F.pos1(f[0]), F.pos1(f[1]), F.pos1(f[2]), P.pos1(p),
                                         union_static_err(P.vbox[ip], F.tbox[face]));
    if (o != Orientation::kUncertain || face_off_vertex_planes(w, P, p, F, face)) {
      ++w.stats.feature_pairs_filtered;
      return;
    }
  }
  ++w.stats.feature_tests;
  Clock::time_point t0;
  if (opt.time_tests) t0 = Clock::now();
  const CcdResult r =
      vertex_face_ccd(v3(P.pos0(p)), v3(F.pos0(f[0])), v3(F.pos0(f[1])), v3(F.pos0(f[2])),
                      v3(P.pos1(p)), v3(F.pos1(f[0])), v3(F.pos1(f[1])), v3(F.pos1(f[2])), opt.ccd);
  if (opt.time_tests) w.tests_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  if (!r.hit()) return;
  Contact c;
  c.kind = ContactKind::kVertexFace;
  c.bodies = {P.body_id, F.body_id};
  c.nodes = {p, f[0], f[1], f[2]};
  c.triangle = face;
  c.at_start = r.outcome == CcdOutcome::kContactAtStart;
  c.toi = c.at_start ? 0.0 : r.toi;
  w.record(c);
}

// Swept boxes of two edges overlap and not all four nodes are still.
inline bool edge_boxes_overlap(const Collider::Impl& A, std::uint32_t e1, const Collider::Impl& B,
                               std::uint32_t e2) noexcept {
  if (!A.edge_moving(e1) && !B.edge_moving(e2)) return false;
  return boxes_overlap(A.edge_box(e1), B.edge_box(e2), A.opt.ccd.min_separation);
}

void process_edge_edge(Worker& w, const Collider::Impl& A, std::uint32_t e1,
                       const Collider::Impl& B, std::uint32_t e2) noexcept {
  if (&A == &B && e1 > e2) std::swap(e1, e2);
  const std::uint32_t a = A.topo->edges[e1][0], b = A.topo->edges[e1][1];
  const std::uint32_t c = B.topo->edges[e2][0], d = B.topo->edges[e2][1];
  const ColliderOptions& opt = A.opt;
  const double ms = opt.ccd.min_separation;
  if (!edge_boxes_overlap(A, e1, B, e2)) return;  // also: all four nodes still
  ++w.stats.feature_pairs;
  if (ms <= 0) {
    // det[b-a, d-c, c-a] = det[b-a, d-a, c-a]: orientation of (a; b, d, c), its points in the
    // union of the two edges' swept boxes (static bound).
    const Orientation o =
        orientation_of(A.pos0(a), A.pos0(b), B.pos0(d), B.pos0(c), A.pos1(a), A.pos1(b), B.pos1(d),
                       B.pos1(c), union_static_err(A.edge_box(e1), B.edge_box(e2)));
    if (o != Orientation::kUncertain || edge_off_face_planes(w, A, e1, B, e2) ||
        edge_off_face_planes(w, B, e2, A, e1)) {
      ++w.stats.feature_pairs_filtered;
      return;
    }
  }
  ++w.stats.feature_tests;
  Clock::time_point t0;
  if (opt.time_tests) t0 = Clock::now();
  const CcdResult r =
      edge_edge_ccd(v3(A.pos0(a)), v3(A.pos0(b)), v3(B.pos0(c)), v3(B.pos0(d)), v3(A.pos1(a)),
                    v3(A.pos1(b)), v3(B.pos1(c)), v3(B.pos1(d)), opt.ccd);
  if (opt.time_tests) w.tests_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  if (!r.hit()) return;
  Contact k;
  k.kind = ContactKind::kEdgeEdge;
  k.bodies = {A.body_id, B.body_id};
  // Edges sorted (a<b, c<d); within one body e1 < e2 in sorted edge order.
  k.nodes = {a, b, c, d};
  k.triangle = 0;
  k.at_start = r.outcome == CcdOutcome::kContactAtStart;
  k.toi = k.at_start ? 0.0 : r.toi;
  w.record(k);
}

// Triangle-pair plane filter of triangle t1 of A and t2 of B (plane_filter.hpp; exact
// contact only; docs/runtime.md, "Triangle-pair plane filter").
// Each triangle's plane comes from w's per-step cache when w caches its body (face_plane),
// else is computed per pair. Same answer either way.
bool plane_separated(Worker& w, const Collider::Impl& A, std::uint32_t t1, const Collider::Impl& B,
                     std::uint32_t t2) noexcept {
  const bool same = &A == &B;
  // Both triangles lie in the union of their swept boxes: its extents bound every coordinate
  // difference of the cubics (the static error bound).
  const orientation_detail::StaticErr err = union_static_err(A.tbox[t1], B.tbox[t2]);
  const auto& n1 = A.tris[t1];
  const auto& n2 = B.tris[t2];
  const MovingTriangle m1{n1, A.x0, A.x1, face_plane(w, A, t1)};
  if (nodes_strictly_on_one_side(m1, MovingTriangle{n2, B.x0, B.x1},
                                 same ? shared_node_mask(n2, n1) : 0, &err))
    return true;  // plane_separated
  const MovingTriangle m2{n2, B.x0, B.x1, face_plane(w, B, t2)};
  return nodes_strictly_on_one_side(m2, m1, same ? shared_node_mask(n1, n2) : 0, &err);
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
  // Edge-edge.
  const auto& EA = A.topo->edges;
  const auto& EB = B.topo->edges;
  for (std::uint32_t i = 0; i < 3; ++i) {
    const std::uint32_t e1 = A.topo->tri_edges[t1][i];
    // tbox[t2] contains the boxes of t2's edges: one check rejects all three.
    if (!boxes_overlap(A.edge_box(e1), B.tbox[t2], ms)) continue;
    for (std::uint32_t j = 0; j < 3; ++j) {
      const std::uint32_t e2 = B.topo->tri_edges[t2][j];
      const auto& E1 = EA[e1];
      const auto& E2 = EB[e2];
      if (same && (E1[0] == E2[0] || E1[0] == E2[1] || E1[1] == E2[0] || E1[1] == E2[1])) continue;
      if (!edge_boxes_overlap(A, e1, B, e2)) continue;
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
      if (owner) process_edge_edge(w, A, e1, B, e2);
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
  for (std::size_t i = 0; i < w.out_written; ++i) add_ring(w.out[i]);
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

bool Collider::Impl::traverse_self(Worker& w, const TreeView& t) const noexcept {
  const double ms = opt.ccd.min_separation;
  // Pair items are tested (not both still, boxes overlap) before they are pushed, so popped
  // pair items are live.
  auto live_pair = [&](std::uint32_t a, std::uint32_t b) {
    if (!rest_mode && t.nmov[a] == 0 && t.nmov[b] == 0) return false;
    return boxes_overlap(t.box[a], t.box[b], ms);
  };
  auto self_pair = [&](std::uint32_t t1, std::uint32_t t2) { process_triangle_pair(w, t1, t2); };
  std::size_t top = 0;
  w.stack[top++] = {0, kNone};
  while (top > 0 && !w.stop) {
    const StackItem it = w.stack[--top];
    ++w.stats.node_pairs_visited;
    if (it.b == kNone) {
      const std::uint32_t n = it.a;
      if (!rest_mode && t.nmov[n] == 0) continue;
      if (t.cone && cone_self_free(*t.cone, t.cone_base + n)) {
        ++w.stats.node_pairs_orientation_culled;
        continue;
      }
      const format::BvhNode& nd = t.nodes[n];
      if (nd.count > 0) {
        for (std::uint32_t i = 0; i < nd.count && !w.stop; ++i)
          for (std::uint32_t j = i + 1; j < nd.count && !w.stop; ++j)
            process_triangle_pair(w, t.leaf_tris[nd.first + i], t.leaf_tris[nd.first + j]);
        continue;
      }
      if (top + 3 > w.stack.size()) return false;
      if (live_pair(nd.first, nd.second)) w.stack[top++] = {nd.first, nd.second};
      w.stack[top++] = {nd.second, kNone};
      w.stack[top++] = {nd.first, kNone};
      continue;
    }
    if (!descend_pair(w, t, t, it, ms, live_pair, self_pair, top)) return false;
  }
  return true;
}

void Collider::Impl::test_orphans(Worker& w) const noexcept {
  for (std::size_t i = 0; i < orphan_vf.size() && !w.stop; ++i)
    process_vertex_face(w, *this, orphan_vf[i][0], *this, orphan_vf[i][1]);
  for (std::size_t i = 0; i < orphan_ee.size() && !w.stop; ++i)
    process_edge_edge(w, *this, orphan_ee[i][0], *this, orphan_ee[i][1]);
}

void Collider::Impl::test_seam_orphans(Worker& w) const noexcept {
  // Each is tested here only when no holding triangle pair is non-culled (otherwise the
  // smallest such pair tests it): exactly once. The cheap rejections of process_* come first.
  const double ms = opt.ccd.min_separation;
  auto nc = [&](std::uint32_t u, std::uint32_t v) { return non_culled(u, v); };
  for (std::size_t i = 0; i < seam_vf.size() && !w.stop; ++i) {
    const std::uint32_t p = seam_vf[i][0], f = seam_vf[i][1];
    const std::uint32_t ip = topo->surf_index[p];
    if (!vmoved[ip] && !tmov[f]) continue;
    if (!boxes_overlap(vbox[ip], tbox[f], ms)) continue;
    if (!any_vertex_face_holder(p, f, nc)) process_vertex_face(w, *this, p, *this, f);
  }
  for (std::size_t i = 0; i < seam_ee.size() && !w.stop; ++i) {
    const std::uint32_t e1 = seam_ee[i][0], e2 = seam_ee[i][1];
    if (!edge_boxes_overlap(*this, e1, *this, e2)) continue;
    if (!any_edge_edge_holder(e1, e2, nc)) process_edge_edge(w, *this, e1, *this, e2);
  }
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

bool Collider::Impl::cluster_tasks(Worker& w, std::uint32_t c1, bool count_skips) const noexcept {
  const std::uint32_t nc = cluster_count();
  const std::uint32_t r1 = topo->wide_root[c1];
  if (r1 == kWideEmpty) return true;
  const bool orient = orientation_mode();
  const bool still = !rest_mode && wmov[r1] == 0;
  if (still || (orient && wsign[r1] != 0)) {
    if (count_skips) ++w.stats.clusters_skipped;
  } else if (!traverse_wide(w, {r1, kNone}, orient)) {
    return false;
  }
  for (std::uint32_t c2 = c1 + 1; c2 < nc && !w.stop; ++c2) {
    const std::uint32_t r2 = topo->wide_root[c2];
    if (r2 == kWideEmpty) continue;
    if (!rest_mode && wmov[r1] == 0 && wmov[r2] == 0) continue;
    if (!boxes_overlap(wbox[r1], wbox[r2], opt.ccd.min_separation)) continue;
    if (!traverse_wide(w, {r1, r2}, false)) return false;
  }
  return true;
}

bool Collider::Impl::run_query(Contact* out, std::size_t out_cap) noexcept {
  const auto t_start = Clock::now();
  for (Worker& w : workers) {
    w.reset();
    w.qkind = qkind;
  }
  Worker& w0 = workers[0];
  w0.out = out;
  w0.out_cap = out ? out_cap : 0;
  const bool count_skips = !stats.full_traversal && qkind == QueryKind::kFull && !rest_mode;
  // Parallel traversal: OpenMP threads take whole tasks (a cluster with its pairs, a brute
  // force vertex or edge); merged in worker order, so counts and the earliest contact equal
  // the serial ones. A caller buffer keeps the serial path (its truncation is order-bound).
  const bool parallel = workers.size() > 1 && out == nullptr && !rest_mode;
  (void)parallel;
  std::uint32_t team = 1;  // threads that ran the traversal
  if (!stats.nothing_moved || rest_mode) {
    const std::uint32_t nc = cluster_count();
    const std::int64_t nv = static_cast<std::int64_t>(topo->surf_nodes.size());
    const std::int64_t ne = static_cast<std::int64_t>(topo->edges.size());
    if (global_bvh_active()) {
      if (tri_count > 0 && !traverse_self(w0, global_view())) w0.overflow = true;
      if (skip_adjacent && !rest_mode && !w0.overflow) test_orphans(w0);
    } else if (opt.mode == ColliderMode::kBrute && !rest_mode) {
#if defined(TETSEG_HAVE_OPENMP)
      if (parallel) {
#pragma omp parallel num_threads(static_cast <int>(workers.size()))
        {
          Worker& w = workers[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp single
          team = static_cast<std::uint32_t>(omp_get_num_threads());
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
#if defined(TETSEG_HAVE_OPENMP)
      if (parallel) {
#pragma omp parallel num_threads(static_cast <int>(workers.size()))
        {
          Worker& w = workers[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp single
          team = static_cast<std::uint32_t>(omp_get_num_threads());
#pragma omp for schedule(dynamic, 1)
          for (std::int64_t c = 0; c < static_cast<std::int64_t>(nc); ++c)
            if (!w.stop && !w.overflow &&
                !cluster_tasks(w, static_cast<std::uint32_t>(c), count_skips))
              w.overflow = true;
        }
      } else
#endif
      {
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
  stats.traversal_threads = team;
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
  out_written = w0.out_written;
  if (qkind == QueryKind::kFull && !rest_mode) {
    stats.full_traversal = true;
    cache.set_full(found, has, first);
  }
  return true;
}

}  // namespace tetseg
