#pragma once
// Triangle-pair plane filter (docs/runtime.md, "Triangle-pair plane filter"). Not installed.

#include <array>
#include <cstdint>

#include "orientation_terms.hpp"

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
    bool decided = false;
    if (err_) {
      const Orientation o = plane_->static_side(p0, p1, *err_, decided);
      if (decided) return o;
    }
    if (!have_full_) set_full();
    return full_.side(f_.p0(f_.nodes[0]), f_.p1(f_.nodes[0]), p0, p1);
  }

 private:
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

/// True when the nodes of `q` that are not nodes of `f` (node ids compared only when
/// `shared_nodes`, i.e. both triangles of one body) stay strictly on one side of f's plane for
/// the whole step, each side proven by the error-bounded orientation cubic (FaceSides).
/// `static_err` (optional): StaticErr::of the extents of a box holding both triangles at both
/// ends of the step; the answer is the same, found with less work.
inline bool nodes_strictly_on_one_side(
    const MovingTriangle& f, const MovingTriangle& q, bool shared_nodes,
    const orientation_detail::StaticErr* static_err = nullptr) noexcept {
  const auto& fn = f.nodes;
  FaceSides sides(f, static_err);
  Orientation side = Orientation::kUncertain;
  for (std::uint32_t n : q.nodes) {
    if (shared_nodes && (n == fn[0] || n == fn[1] || n == fn[2])) continue;
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
  return nodes_strictly_on_one_side(t1, t2, shared_nodes, static_err) ||
         nodes_strictly_on_one_side(t2, t1, shared_nodes, static_err);
}

}  // namespace tetseg
