#pragma once
// Triangle-pair plane filter (docs/runtime.md, "Triangle-pair plane filter"). Not installed.

#include <array>
#include <cstdint>

#include "orientation_terms.hpp"

namespace tetseg {

/// A triangle moving linearly over a step: node ids and the position arrays they index
/// (node n at x0 + 3n at the start, x1 + 3n at the end), and optionally its plane's minors for
/// this step (`FacePlaneMinors::of` of its nodes in order; computed here when null).
struct MovingTriangle {
  std::array<std::uint32_t, 3> nodes;
  const double* x0;
  const double* x1;
  const FacePlaneMinors* minors = nullptr;
  const double* p0(std::uint32_t n) const noexcept { return x0 + std::size_t(n) * 3; }
  const double* p1(std::uint32_t n) const noexcept { return x1 + std::size_t(n) * 3; }
};

/// True when the nodes of `q` that are not nodes of `f` (node ids compared only when
/// `shared_nodes`, i.e. both triangles of one body) stay strictly on one side of f's plane for
/// the whole step, each side proven by the error-bounded orientation cubic. f's plane is
/// computed at most once for the up to three points (not at all when f carries its minors).
/// `static_err` (optional): StaticErr::of the extents of a box holding both triangles at both
/// ends of the step; the answer is the same, found with less work.
inline bool nodes_strictly_on_one_side(
    const MovingTriangle& f, const MovingTriangle& q, bool shared_nodes,
    const orientation_detail::StaticErr* static_err = nullptr) noexcept {
  const auto& fn = f.nodes;
  const double* a0 = f.p0(fn[0]);
  const double* a1 = f.p1(fn[0]);
  FacePlaneMinors local;
  const FacePlaneMinors* plane = f.minors;
  if (!plane) {
    local = FacePlaneMinors::of(a0, f.p0(fn[1]), f.p0(fn[2]), a1, f.p1(fn[1]), f.p1(fn[2]));
    plane = &local;
  }
  Orientation side = Orientation::kUncertain;
  for (std::uint32_t n : q.nodes) {
    if (shared_nodes && (n == fn[0] || n == fn[1] || n == fn[2])) continue;
    const Orientation o = static_err ? plane->side(a0, a1, q.p0(n), q.p1(n), *static_err)
                                     : plane->side(a0, a1, q.p0(n), q.p1(n));
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
inline bool plane_separated(const MovingTriangle& t1, const MovingTriangle& t2,
                            bool shared_nodes) noexcept {
  return nodes_strictly_on_one_side(t1, t2, shared_nodes) ||
         nodes_strictly_on_one_side(t2, t1, shared_nodes);
}

}  // namespace tetseg
