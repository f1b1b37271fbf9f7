#pragma once
/// \file
/// Exact rational continuous collision detection: the truth the runtime's elementary tests
/// (runtime/ccd.hpp) are held to. Inputs are doubles taken as exact rationals; every point
/// moves as x(t) = x0 + t (x1 - x0), t in [0, 1]; contact = the closed point and triangle (the
/// closed segments) share a point at some real t in [0, 1]. No tolerance, no separation
/// distance: degenerate input (coplanar for the step or at an end, touching at t = 0 or 1,
/// sliding in a plane, zero-area triangles, parallel / collinear / zero-length edges, zero
/// motion) is decided exactly like any other. Test-only (GMP); shares no code with the runtime.
///
/// Method. Touching at t is a disjunction of polynomial sign conditions in t:
///   vertex-face: [f = 0, |n|^2 != 0, g_a, g_b, g_c >= 0]  or  p on one of the three edges;
///   edge-edge:   [f = 0, |m|^2 != 0, s, 1-s, u, 1-u >= 0 (times |m|^2)]  or  an endpoint on
///                the other segment;
/// with f the coplanarity cubic, n the triangle normal, g the barycentric areas times n,
/// m = (b-a) x (d-c), and "x on [y, z]" = [(x-y) x (z-y) = 0, (x-y).(x-z) <= 0]. The contact
/// set is closed, so its first point is 0 or a real root of one of these polynomials (of f
/// alone unless f vanishes identically); each candidate root is isolated (Sturm) and the
/// conditions are decided at it exactly (exact_poly.hpp's sign_at). Swept boxes and the
/// Bernstein signs of f reject most misses before any root is isolated.

#include <algorithm>
#include <array>
#include <optional>
#include <vector>

#include "tetseg/runtime/ccd.hpp"  // Vec3d only
#include "tetseg/testing/exact_poly.hpp"

namespace tetseg::test {

struct ExactCcd {
  bool hit = false;        ///< exists t in [0,1] with the closed primitives touching (exact)
  bool at_start = false;   ///< touching at t = 0
  double toi_upper = 1.0;  ///< the exact first contact time rounded up (valid when hit)
  double toi_lower = 1.0;  ///< the exact first contact time rounded down (valid when hit)
};

namespace exact_ccd_detail {

using exact::Poly;
using QVec = std::array<Poly, 3>;  // a vector whose coordinates are polynomials in t

/// x0 + t (x1 - x0), coordinate by coordinate.
inline QVec trajectory(const Vec3d& x0, const Vec3d& x1) {
  QVec v;
  for (int k = 0; k < 3; ++k) {
    const mpq_class a(x0[k]), b(x1[k]);
    v[k] = Poly{a, b - a};
    exact::trim(v[k]);
  }
  return v;
}

inline QVec minus(const QVec& a, const QVec& b) {
  return {exact::sub(a[0], b[0]), exact::sub(a[1], b[1]), exact::sub(a[2], b[2])};
}

inline QVec cross(const QVec& a, const QVec& b) {
  using exact::mul;
  using exact::sub;
  return {sub(mul(a[1], b[2]), mul(a[2], b[1])), sub(mul(a[2], b[0]), mul(a[0], b[2])),
          sub(mul(a[0], b[1]), mul(a[1], b[0]))};
}

inline Poly dot(const QVec& a, const QVec& b) {
  using exact::add;
  using exact::mul;
  return add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]));
}

/// "x on the closed segment [y, z]" at time t: cross == 0 (all three) and along <= 0.
struct OnSegment {
  QVec cross;
  Poly along;
};

inline OnSegment on_segment(const QVec& x, const QVec& y, const QVec& z) {
  const QVec xy = minus(x, y);
  return {cross(xy, minus(z, y)), dot(xy, minus(x, z))};
}

inline bool holds_at(const OnSegment& s, exact::RealRoot& t) {
  for (const Poly& c : s.cross)
    if (exact::sign_at(c, t) != 0) return false;
  return exact::sign_at(s.along, t) <= 0;
}

/// The general clause [f = 0, |normal|^2 != 0, every inside >= 0] and the point-on-segment
/// clauses of one query.
struct Clauses {
  Poly f;
  Poly normal_sq;
  std::vector<Poly> inside;
  std::vector<OnSegment> segments;

  bool touching_at(exact::RealRoot& t) {
    if (exact::sign_at(f, t) != 0) return false;  // every clause implies coplanarity
    if (exact::sign_at(normal_sq, t) != 0) {
      bool in = true;
      for (const Poly& g : inside)
        if (exact::sign_at(g, t) < 0) {
          in = false;
          break;
        }
      if (in) return true;
    }
    for (const OnSegment& s : segments)
      if (holds_at(s, t)) return true;
    return false;
  }

  /// Every polynomial whose roots may start the contact set (besides t = 0).
  std::vector<Poly> candidate_polynomials() const {
    if (!f.empty()) return {f};
    std::vector<Poly> c;
    if (!normal_sq.empty())
      for (const Poly& g : inside)
        if (exact::degree(g) >= 1) c.push_back(g);
    for (const OnSegment& s : segments) {
      // The common roots of the cross coordinates; when they all vanish identically (collinear
      // for the whole step), the roots of `along`.
      const Poly common = exact::gcd(exact::gcd(s.cross[0], s.cross[1]), s.cross[2]);
      if (exact::degree(common) >= 1) c.push_back(common);
      if (common.empty() && exact::degree(s.along) >= 1) c.push_back(s.along);
    }
    return c;
  }
};

inline ExactCcd solve(Clauses& q) {
  ExactCcd out;
  if (!q.f.empty() && exact::bernstein_no_root_in_unit_interval(q.f)) return out;
  exact::RealRoot zero = exact::RealRoot::rational(0);
  if (q.touching_at(zero)) {
    out.hit = out.at_start = true;
    out.toi_upper = out.toi_lower = 0.0;
    return out;
  }
  // The first touching root of each candidate polynomial; the minimum over them (rounding is
  // monotone, so the rounded minimum is the minimum of the rounded roots).
  std::optional<exact::RealRoot> best;
  for (const Poly& p : q.candidate_polynomials()) {
    for (exact::RealRoot& r : exact::roots_in_unit_interval(p)) {
      if (best && r.lo >= best->hi) break;  // cannot come first
      if (!q.touching_at(r)) continue;
      const auto [lower, upper] = exact::enclose(r);
      if (!out.hit || upper < out.toi_upper) out.toi_upper = upper;
      if (!out.hit || lower < out.toi_lower) out.toi_lower = lower;
      out.hit = true;
      if (!best || r.hi < best->hi) best = r;
      break;
    }
  }
  return out;
}

inline bool boxes_disjoint(std::initializer_list<const Vec3d*> a,
                           std::initializer_list<const Vec3d*> b) {
  for (int k = 0; k < 3; ++k) {
    double alo = INFINITY, ahi = -INFINITY, blo = INFINITY, bhi = -INFINITY;
    for (const Vec3d* p : a) alo = std::min(alo, (*p)[k]), ahi = std::max(ahi, (*p)[k]);
    for (const Vec3d* p : b) blo = std::min(blo, (*p)[k]), bhi = std::max(bhi, (*p)[k]);
    if (ahi < blo || bhi < alo) return true;
  }
  return false;
}

}  // namespace exact_ccd_detail

/// Vertex p against the closed triangle (a, b, c); suffix 0 = start of the step, 1 = end.
inline ExactCcd exact_vertex_face(const Vec3d& p0, const Vec3d& a0, const Vec3d& b0,
                                  const Vec3d& c0, const Vec3d& p1, const Vec3d& a1,
                                  const Vec3d& b1, const Vec3d& c1) {
  namespace d = exact_ccd_detail;
  if (d::boxes_disjoint({&p0, &p1}, {&a0, &b0, &c0, &a1, &b1, &c1})) return {};
  const d::QVec p = d::trajectory(p0, p1), a = d::trajectory(a0, a1), b = d::trajectory(b0, b1),
                c = d::trajectory(c0, c1);
  const d::QVec ap = d::minus(a, p), bp = d::minus(b, p), cp = d::minus(c, p);
  d::Clauses q;
  q.f = d::dot(ap, d::cross(bp, cp));
  if (!q.f.empty() && exact::bernstein_no_root_in_unit_interval(q.f)) return {};
  const d::QVec n = d::cross(d::minus(b, a), d::minus(c, a));
  q.normal_sq = d::dot(n, n);
  q.inside = {d::dot(d::cross(bp, cp), n), d::dot(d::cross(cp, ap), n),
              d::dot(d::cross(ap, bp), n)};
  q.segments = {d::on_segment(p, a, b), d::on_segment(p, b, c), d::on_segment(p, c, a)};
  return d::solve(q);
}

/// Closed segment (a, b) against closed segment (c, d).
inline ExactCcd exact_edge_edge(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                                const Vec3d& a1, const Vec3d& b1, const Vec3d& c1,
                                const Vec3d& d1) {
  namespace x = exact_ccd_detail;
  if (x::boxes_disjoint({&a0, &b0, &a1, &b1}, {&c0, &d0, &c1, &d1})) return {};
  const x::QVec a = x::trajectory(a0, a1), b = x::trajectory(b0, b1), c = x::trajectory(c0, c1),
                d = x::trajectory(d0, d1);
  const x::QVec e1 = x::minus(b, a), e2 = x::minus(d, c), w = x::minus(c, a);
  x::Clauses q;
  q.f = x::dot(e1, x::cross(w, x::minus(d, a)));
  if (!q.f.empty() && exact::bernstein_no_root_in_unit_interval(q.f)) return {};
  const x::QVec m = x::cross(e1, e2);
  q.normal_sq = x::dot(m, m);
  // With a + s e1 = c + u e2 in the plane: s |m|^2 = (w x e2).m, u |m|^2 = (w x e1).m.
  const exact::Poly s = x::dot(x::cross(w, e2), m), u = x::dot(x::cross(w, e1), m);
  q.inside = {s, exact::sub(q.normal_sq, s), u, exact::sub(q.normal_sq, u)};
  q.segments = {x::on_segment(a, c, d), x::on_segment(b, c, d), x::on_segment(c, a, b),
                x::on_segment(d, a, b)};
  return x::solve(q);
}

}  // namespace tetseg::test
