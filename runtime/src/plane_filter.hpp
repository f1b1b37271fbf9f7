#pragma once
// Triangle-pair plane filter (docs/runtime.md, "Triangle-pair plane filter"). Not installed.

#include <array>
#include <cstdint>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "orientation_terms.hpp"

// Keeps a rarely taken path out of its hot caller (a hint; nothing depends on it).
#if defined(__GNUC__)
#define TETSEG_NOINLINE __attribute__((noinline))
#else
#define TETSEG_NOINLINE
#endif

namespace tetseg {

/// A triangle moving linearly over a step: node ids and the position arrays they index
/// (node n at x0 + 3n at the start, x1 + 3n at the end), and optionally its plane for this
/// step (`FacePlaneStatic::of` of its nodes in order; computed when needed if null).
struct MovingTriangle {
  std::array<std::uint32_t, 3> nodes;
  const double* x0;
  const double* x1;
  const FacePlaneStatic* plane = nullptr;
  const double* p0(std::uint32_t n) const noexcept { return x0 + std::size_t(n) * 3; }
  const double* p1(std::uint32_t n) const noexcept { return x1 + std::size_t(n) * 3; }
};

/// The sides of points with respect to the plane of a moving triangle f over the step, each
/// bitwise `classify_orientation(a0, p0, b0, c0, a1, p1, b1, c1)` for f = (a, b, c): with a
/// static error bound (StaticErr::of the extents of a box holding f and every point asked
/// about, at both ends of the step) from f's FacePlaneStatic first, the full error-bounded
/// cubic (FacePlaneMinors, computed at most once) when the static bound does not decide.
class FaceSides {
 public:
  FaceSides(const MovingTriangle& f, const orientation_detail::StaticErr* static_err) noexcept
      : f_(f), err_(static_err), plane_(f.plane) {
    if (!err_) {
      set_full();
    } else if (!plane_) {
      local_ = FacePlaneStatic::of(f.p0(f.nodes[0]), f.p0(f.nodes[1]), f.p0(f.nodes[2]),
                                   f.p1(f.nodes[0]), f.p1(f.nodes[1]), f.p1(f.nodes[2]));
      plane_ = &local_;
    }
  }
  Orientation of(const double* p0, const double* p1) noexcept {
    if (err_) {
      bool decided;
      const Orientation o = plane_->static_side(p0, p1, *err_, decided);
      if (decided) return o;
    }
    return full_side(p0, p1);
  }

 private:
  // The full cubic (kept out of line: the static bound usually decides).
  TETSEG_NOINLINE Orientation full_side(const double* p0, const double* p1) noexcept {
    if (!have_full_) set_full();
    return full_.side(f_.p0(f_.nodes[0]), f_.p1(f_.nodes[0]), p0, p1);
  }
  void set_full() noexcept {
    const auto& n = f_.nodes;
    full_ = FacePlaneMinors::of(f_.p0(n[0]), f_.p0(n[1]), f_.p0(n[2]), f_.p1(n[0]), f_.p1(n[1]),
                                f_.p1(n[2]));
    have_full_ = true;
  }
  const MovingTriangle& f_;
  const orientation_detail::StaticErr* err_;
  const FacePlaneStatic* plane_;
  FacePlaneStatic local_;
  FacePlaneMinors full_;  // computed at the first point the static bound does not decide
  bool have_full_ = false;
};

/// Bit i set when node i of `q` is a node of `f` (node ids of one body).
inline unsigned shared_node_mask(const std::array<std::uint32_t, 3>& q,
                                 const std::array<std::uint32_t, 3>& f) noexcept {
#if defined(__SSE2__)
  // q's ids in lanes 0-2 (lane 3 repeats q[2] and is masked off) against each id of f.
  const __m128i qv = _mm_setr_epi32(int(q[0]), int(q[1]), int(q[2]), int(q[2]));
  const __m128i eq = _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi32(qv, _mm_set1_epi32(int(f[0]))),
                                               _mm_cmpeq_epi32(qv, _mm_set1_epi32(int(f[1])))),
                                  _mm_cmpeq_epi32(qv, _mm_set1_epi32(int(f[2]))));
  return unsigned(_mm_movemask_ps(_mm_castsi128_ps(eq))) & 7u;
#else
  unsigned mask = 0;
  for (unsigned i = 0; i < 3; ++i)
    mask |= unsigned((q[i] == f[0]) | (q[i] == f[1]) | (q[i] == f[2])) << i;
  return mask;
#endif
}

/// True when the nodes of `q` outside `skip` (bit i: node i; the nodes q shares with f, see
/// shared_node_mask) stay strictly on one side of f's plane for the whole step, each side
/// proven by the error-bounded orientation cubic (FaceSides). `static_err` (optional):
/// StaticErr::of the extents of a box holding both triangles at both ends of the step; the
/// answer is the same, found with less work.
inline bool nodes_strictly_on_one_side(
    const MovingTriangle& f, const MovingTriangle& q, unsigned skip,
    const orientation_detail::StaticErr* static_err = nullptr) noexcept {
  FaceSides sides(f, static_err);
  Orientation side = Orientation::kUncertain;
  for (unsigned i = 0; i < 3; ++i) {
    if (skip & (1u << i)) continue;
    const std::uint32_t n = q.nodes[i];
    const Orientation o = sides.of(q.p0(n), q.p1(n));
    if (o == Orientation::kUncertain || (side != Orientation::kUncertain && o != side))
      return false;
    side = o;
  }
  return true;
}

/// The plane filter: the unshared nodes of one triangle stay strictly on one side of the other
/// triangle's plane for the whole step. Then the triangles meet at most in their shared nodes,
/// and no feature pair of them with four distinct nodes (vertex-face, edge-edge) can touch.
/// For exact contact (min_separation = 0) only.
/// `static_err` (optional): as for nodes_strictly_on_one_side; the same answer.
inline bool plane_separated(const MovingTriangle& t1, const MovingTriangle& t2, bool shared_nodes,
                            const orientation_detail::StaticErr* static_err = nullptr) noexcept {
  const unsigned skip2 = shared_nodes ? shared_node_mask(t2.nodes, t1.nodes) : 0;
  const unsigned skip1 = shared_nodes ? shared_node_mask(t1.nodes, t2.nodes) : 0;
  return nodes_strictly_on_one_side(t1, t2, skip2, static_err) ||
         nodes_strictly_on_one_side(t2, t1, skip1, static_err);
}

}  // namespace tetseg
