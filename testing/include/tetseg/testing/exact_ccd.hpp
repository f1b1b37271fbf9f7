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
/// the same conditions in outward-rounded interval arithmetic over a subdivision of [0, 1],
/// then the exact Bernstein signs of f, reject most misses before any root is isolated.

#include <algorithm>
#include <array>
#include <cmath>
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

/// A closed interval of doubles, widened outward after every operation: a cheap rigorous
/// enclosure. A round-to-nearest result r errs by at most half an ulp (2^-1075 when
/// subnormal); r -/+ (|r| 2^-51 + 2^-1074), itself rounded, moves by at least one ulp past
/// it (infinities give NaN, which no filter accepts).
struct Interval {
  double lo, hi;
};
inline double down(double x) {
  return x - (std::abs(x) * 0x1p-51 + 0x1p-1074);
}
inline double up(double x) {
  return x + (std::abs(x) * 0x1p-51 + 0x1p-1074);
}
inline Interval operator+(Interval a, Interval b) {
  return {down(a.lo + b.lo), up(a.hi + b.hi)};
}
inline Interval operator-(Interval a, Interval b) {
  return {down(a.lo - b.hi), up(a.hi - b.lo)};
}
inline Interval operator*(Interval a, Interval b) {
  const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  return {down(std::min({p[0], p[1], p[2], p[3]})), up(std::max({p[0], p[1], p[2], p[3]}))};
}
/// Polynomials in t with interval coefficients, lowest degree first.
using IPoly = std::vector<Interval>;
using IQVec = std::array<IPoly, 3>;

inline IPoly operator+(const IPoly& a, const IPoly& b) {
  IPoly r(std::max(a.size(), b.size()), Interval{0, 0});
  for (std::size_t i = 0; i < a.size(); ++i) r[i] = r[i] + a[i];
  for (std::size_t i = 0; i < b.size(); ++i) r[i] = r[i] + b[i];
  return r;
}
inline IPoly operator-(const IPoly& a, const IPoly& b) {
  IPoly r(std::max(a.size(), b.size()), Interval{0, 0});
  for (std::size_t i = 0; i < a.size(); ++i) r[i] = r[i] + a[i];
  for (std::size_t i = 0; i < b.size(); ++i) r[i] = r[i] - b[i];
  return r;
}
inline IPoly operator*(const IPoly& a, const IPoly& b) {
  IPoly r(a.size() + b.size() - 1, Interval{0, 0});
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) r[i + j] = r[i + j] + a[i] * b[j];
  return r;
}
inline IQVec operator-(const IQVec& a, const IQVec& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline IQVec icross(const IQVec& a, const IQVec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline IPoly idot(const IQVec& a, const IQVec& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline IQVec itrajectory(const Vec3d& x0, const Vec3d& x1) {
  IQVec v;
  for (int k = 0; k < 3; ++k)
    v[k] = {Interval{x0[k], x0[k]}, Interval{x1[k], x1[k]} - Interval{x0[k], x0[k]}};
  return v;
}
/// An enclosure of p over t in [lo, hi] (0 <= lo <= hi), by Horner's rule.
inline Interval enclosure(const IPoly& p, double lo, double hi) {
  Interval v{0, 0};
  for (std::size_t i = p.size(); i-- > 0;) v = v * Interval{lo, hi} + p[i];
  return v;
}

/// True when the primitives provably never touch: on every piece of a subdivision of [0, 1]
/// the enclosure of the coplanarity polynomial `f` excludes 0, or one of the `inside`
/// polynomials (which are all >= 0 wherever the primitives touch) is strictly negative. A
/// fast rejection, rigorous in floating point; false says nothing.
inline bool provably_apart(const IPoly& f, const std::vector<IPoly>& inside) {
  struct Piece {
    double lo, hi;
    int depth;
  };
  Piece stack[16];
  int size = 0;
  stack[size++] = {0.0, 1.0, 0};
  while (size > 0) {
    const Piece t = stack[--size];
    const Interval fv = enclosure(f, t.lo, t.hi);
    if (fv.lo > 0 || fv.hi < 0) continue;
    bool outside = false;
    for (const IPoly& g : inside) {
      if (enclosure(g, t.lo, t.hi).hi < 0) {
        outside = true;
        break;
      }
    }
    if (outside) continue;
    if (t.depth == 5) return false;
    const double mid = 0.5 * (t.lo + t.hi);
    stack[size++] = {mid, t.hi, t.depth + 1};
    stack[size++] = {t.lo, mid, t.depth + 1};
  }
  return true;
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
  {
    const d::IQVec p = d::itrajectory(p0, p1), a = d::itrajectory(a0, a1),
                   b = d::itrajectory(b0, b1), c = d::itrajectory(c0, c1);
    const d::IQVec ap = a - p, bp = b - p, cp = c - p, n = d::icross(b - a, c - a);
    if (d::provably_apart(d::idot(ap, d::icross(bp, cp)),
                          {d::idot(d::icross(bp, cp), n), d::idot(d::icross(cp, ap), n),
                           d::idot(d::icross(ap, bp), n)}))
      return {};
  }
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
  {
    const x::IQVec a = x::itrajectory(a0, a1), b = x::itrajectory(b0, b1),
                   c = x::itrajectory(c0, c1), d = x::itrajectory(d0, d1);
    const x::IQVec e1 = b - a, e2 = d - c, w = c - a, m = x::icross(e1, e2);
    const x::IPoly mm = x::idot(m, m), s = x::idot(x::icross(w, e2), m),
                   u = x::idot(x::icross(w, e1), m);
    if (x::provably_apart(x::idot(e1, x::icross(w, d - a)), {s, mm - s, u, mm - u})) return {};
  }
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
