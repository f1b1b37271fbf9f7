// Collider narrow phase: one feature pair (vertex-face or edge-edge) of two triangles through
// the still rule, its swept boxes, the coplanarity and plane filters and the elementary test,
// into a contact; and the triangle-pair plane filter. Deduplication (which triangle pair tests
// which feature pair) is the traversal's: collider_traverse.cpp.

#include <algorithm>
#include <chrono>

#include "collider_impl.hpp"
#include "plane_filter.hpp"

namespace tetseg {
namespace {

inline Vec3d v3(const double* p) noexcept {
  return {p[0], p[1], p[2]};
}

}  // namespace

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
  if (sink) sink->add(c);
}

namespace {

void add_to_heap(ContactSink& s, const Contact& c) noexcept {
  if (s.written < s.cap) {
    s.out[s.written++] = c;
    std::push_heap(s.out, s.out + s.written, contact_less);
  } else if (s.cap > 0 && contact_less(c, s.out[0])) {
    std::pop_heap(s.out, s.out + s.cap, contact_less);
    s.out[s.cap - 1] = c;
    std::push_heap(s.out, s.out + s.cap, contact_less);
  }
}

}  // namespace

void ContactSink::add(const Contact& c) noexcept {
#if defined(TETSEG_HAVE_OPENMP)
  if (locked) {
#pragma omp critical(tetseg_contact_sink)
    add_to_heap(*this, c);
    return;
  }
#endif
  add_to_heap(*this, c);
}

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
// `box2`: e2's swept box (B.edge_box(e2)).
bool edge_off_face_planes(Worker& w, const Collider::Impl& A, std::uint32_t e1,
                          const Collider::Impl& B, std::uint32_t e2, const Box& box2) noexcept {
  const auto& et_offset = A.topo->et_offset;
  for (std::uint32_t k = et_offset[e1]; k < et_offset[e1 + 1]; ++k)
    if (nodes_off_plane(w, A, A.topo->et_list[k], B, B.topo->edges[e2].data(), 2, box2))
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

// The elementary test `ccd` (a call returning its CcdResult), timed when the options ask, and
// its contact recorded: `c` names the features (kind, bodies, nodes, triangle); the outcome
// sets its time.
template <class Ccd>
void test_and_record(Worker& w, const ColliderOptions& opt, Ccd&& ccd, Contact c) noexcept {
  ++w.stats.feature_tests;
  Clock::time_point t0;
  if (opt.time_tests) t0 = Clock::now();
  const CcdResult r = ccd();
  if (opt.time_tests) w.tests_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  if (!r.hit()) return;
  c.at_start = r.outcome == CcdOutcome::kContactAtStart;
  c.toi = c.at_start ? 0.0 : r.toi;
  w.record(c);
}

// What follows a feature pair's coplanarity filter when that did not reject it: the plane
// filters (exact contact only), then the elementary test. Out of line: inlined, the compiler
// kept the filter's 24 coordinates for the test and spilled them on every pair, nearly all of
// which the filter rejects.
TETSEG_NOINLINE void vertex_face_after_coplanarity(Worker& w, const Collider::Impl& P,
                                                   std::uint32_t p, const Collider::Impl& F,
                                                   std::uint32_t face) noexcept {
  const ColliderOptions& opt = P.opt;
  if (opt.ccd.min_separation <= 0 && face_off_vertex_planes(w, P, p, F, face)) {
    ++w.stats.feature_pairs_filtered;
    return;
  }
  const auto& f = F.tris[face];
  Contact c;
  c.kind = ContactKind::kVertexFace;
  c.bodies = {P.body_id, F.body_id};
  c.nodes = {p, f[0], f[1], f[2]};
  c.triangle = face;
  test_and_record(
      w, opt,
      [&] {
        return vertex_face_ccd(v3(P.pos0(p)), v3(F.pos0(f[0])), v3(F.pos0(f[1])), v3(F.pos0(f[2])),
                               v3(P.pos1(p)), v3(F.pos1(f[0])), v3(F.pos1(f[1])), v3(F.pos1(f[2])),
                               opt.ccd);
      },
      c);
}

// As vertex_face_after_coplanarity: edge e1 of A, e2 of B in the order of the contact, with
// their swept boxes.
TETSEG_NOINLINE void edge_edge_after_coplanarity(Worker& w, const Collider::Impl& A,
                                                 std::uint32_t e1, const Box& box1,
                                                 const Collider::Impl& B, std::uint32_t e2,
                                                 const Box& box2) noexcept {
  const ColliderOptions& opt = A.opt;
  if (opt.ccd.min_separation <= 0 && (edge_off_face_planes(w, A, e1, B, e2, box2) ||
                                      edge_off_face_planes(w, B, e2, A, e1, box1))) {
    ++w.stats.feature_pairs_filtered;
    return;
  }
  const std::uint32_t a = A.topo->edges[e1][0], b = A.topo->edges[e1][1];
  const std::uint32_t c = B.topo->edges[e2][0], d = B.topo->edges[e2][1];
  Contact k;
  k.kind = ContactKind::kEdgeEdge;
  k.bodies = {A.body_id, B.body_id};
  // Edges sorted (a<b, c<d); within one body e1 < e2 in sorted edge order.
  k.nodes = {a, b, c, d};
  k.triangle = 0;
  test_and_record(
      w, opt,
      [&] {
        return edge_edge_ccd(v3(A.pos0(a)), v3(A.pos0(b)), v3(B.pos0(c)), v3(B.pos0(d)),
                             v3(A.pos1(a)), v3(A.pos1(b)), v3(B.pos1(c)), v3(B.pos1(d)), opt.ccd);
      },
      k);
}

}  // namespace

void process_vertex_face(Worker& w, const Collider::Impl& P, std::uint32_t p,
                         const Collider::Impl& F, std::uint32_t face) noexcept {
  const auto& f = F.tris[face];
  const std::uint32_t ip = P.topo->surf_index[p];
  if (!P.vmoved[ip] && !F.tmov[face]) return;  // still feature pair: only t = 0 contact possible
  const double ms = P.opt.ccd.min_separation;
  if (!boxes_overlap(P.vbox[ip], F.tbox[face], ms)) return;
  ++w.stats.feature_pairs;
  if (ms <= 0) {
    // Coplanarity cubic det[b-a, c-a, p-a] with a proven strict sign: never coplanar. Its
    // points lie in the union of the vertex's and the face's swept boxes (static bound).
    const Orientation o = orientation_of(F.pos0(f[0]), F.pos0(f[1]), F.pos0(f[2]), P.pos0(p),
                                         F.pos1(f[0]), F.pos1(f[1]), F.pos1(f[2]), P.pos1(p),
                                         union_static_err(P.vbox[ip], F.tbox[face]));
    if (o != Orientation::kUncertain) {
      ++w.stats.feature_pairs_filtered;
      return;
    }
  }
  vertex_face_after_coplanarity(w, P, p, F, face);
}

void process_edge_edge(Worker& w, const Collider::Impl& A, std::uint32_t e1,
                       const Collider::Impl& B, std::uint32_t e2) noexcept {
  if (!A.edge_moving(e1) && !B.edge_moving(e2)) return;  // all four nodes still
  const Box box1 = A.edge_box(e1), box2 = B.edge_box(e2);
  if (!boxes_overlap(box1, box2, A.opt.ccd.min_separation)) return;
  process_edge_edge(w, A, e1, box1, B, e2, box2);
}

void process_edge_edge(Worker& w, const Collider::Impl& A, std::uint32_t e1, const Box& box1_in,
                       const Collider::Impl& B, std::uint32_t e2, const Box& box2_in) noexcept {
  const Box* box1 = &box1_in;
  const Box* box2 = &box2_in;
  if (&A == &B && e1 > e2) {
    std::swap(e1, e2);
    std::swap(box1, box2);
  }
  if (!A.edge_moving(e1) && !B.edge_moving(e2)) return;  // all four nodes still
  const double ms = A.opt.ccd.min_separation;
  ++w.stats.feature_pairs;
  if (ms <= 0) {
    // det[b-a, d-c, c-a] = det[b-a, d-a, c-a]: orientation of (a; b, d, c), its points in the
    // union of the two edges' swept boxes (static bound).
    const std::uint32_t a = A.topo->edges[e1][0], b = A.topo->edges[e1][1];
    const std::uint32_t c = B.topo->edges[e2][0], d = B.topo->edges[e2][1];
    const Orientation o =
        orientation_of(A.pos0(a), A.pos0(b), B.pos0(d), B.pos0(c), A.pos1(a), A.pos1(b), B.pos1(d),
                       B.pos1(c), union_static_err(*box1, *box2));
    if (o != Orientation::kUncertain) {
      ++w.stats.feature_pairs_filtered;
      return;
    }
  }
  edge_edge_after_coplanarity(w, A, e1, *box1, B, e2, *box2);
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

}  // namespace tetseg
