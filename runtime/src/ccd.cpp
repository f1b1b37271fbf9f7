// Elementary continuous collision tests: vertex-face and edge-edge, linear trajectories.
//
// Method (docs/ccd.md): bisection in time only. On a time interval T every vector used
// (differences of moving points) is affine in t, so every quantity below is a multilinear form
// of such vectors, i.e. a polynomial in t whose Bernstein coefficients on T are averages of
// the form evaluated at the interval ends. Those coefficients are enclosed with rigorous
// interval arithmetic (ccd_interval.hpp); by the convex-hull property they bound the
// polynomial on T. T is excluded when one necessary condition of contact provably fails on
// all of T: swept boxes disjoint, the coplanarity cubic of one sign, or the point (the other
// edge) strictly on the outer side of one edge plane. Unexcluded intervals are split, left
// first, down to options.time_tolerance; the first unexcluded leaf is reported with toi = its
// start, so every time before toi was proved contact-free.

#include <algorithm>
#include <cmath>

#include "ccd_interval.hpp"
#include "tetseg/runtime/ccd.hpp"

namespace tetseg {
namespace {

using namespace ccd_detail;

constexpr int kStackSize = 64;
constexpr double kMinTolerance = 0x1p-50;

IvVec exact_vec(const Vec3d& x) noexcept {
  return {exact(x[0]), exact(x[1]), exact(x[2])};
}

/// Enclosure of x0 + t (x1 - x0) for an exact time t.
IvVec position(const Vec3d& x0, const Vec3d& x1, double t) noexcept {
  if (t == 0.0) return exact_vec(x0);
  if (t == 1.0) return exact_vec(x1);
  const Iv tt = exact(t);
  return {exact(x0[0]) + tt * (exact(x1[0]) - exact(x0[0])),
          exact(x0[1]) + tt * (exact(x1[1]) - exact(x0[1])),
          exact(x0[2]) + tt * (exact(x1[2]) - exact(x0[2]))};
}

/// A vector affine in t over the current interval: enclosures of its values at both ends.
struct Slot {
  IvVec v[2];
};

Slot difference(const IvVec (&x)[2], const IvVec (&y)[2]) noexcept {
  return {{x[0] - y[0], x[1] - y[1]}};
}

Range range_of(const Iv* coefficients, int count) noexcept {
  Range r{lower(coefficients[0]), upper(coefficients[0])};
  for (int i = 1; i < count; ++i) {
    r.lo = min_nan(r.lo, lower(coefficients[i]));
    r.hi = max_nan(r.hi, upper(coefficients[i]));
  }
  // NaN anywhere makes the range useless: widen to everything.
  if (std::isnan(r.lo) || std::isnan(r.hi)) r = {-INFINITY, INFINITY};
  return r;
}

/// Bernstein enclosure of the bilinear form w1 . w2 over the interval.
Range bilinear_range(const Slot& w1, const Slot& w2) noexcept {
  const Iv b0 = dot(w1.v[0], w2.v[0]);
  const Iv b1 = divide(dot(w1.v[1], w2.v[0]) + dot(w1.v[0], w2.v[1]), 2.0);
  const Iv b2 = dot(w1.v[1], w2.v[1]);
  const Iv b[3] = {b0, b1, b2};
  return range_of(b, 3);
}

/// Bernstein enclosure of the trilinear form (w1 x w2) . w3 over the interval.
Range trilinear_range(const Slot& w1, const Slot& w2, const Slot& w3) noexcept {
  Iv sum[4] = {exact(0), exact(0), exact(0), exact(0)};
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      const IvVec c = cross(w1.v[i], w2.v[j]);
      for (int k = 0; k < 2; ++k) sum[i + j + k] = sum[i + j + k] + dot(c, w3.v[k]);
    }
  }
  const Iv b[4] = {sum[0], divide(sum[1], 3.0), divide(sum[2], 3.0), sum[3]};
  return range_of(b, 4);
}

/// Bernstein enclosure of the quadrilinear form (w1 x w2) . (w3 x w4) over the interval.
Range quadrilinear_range(const Slot& w1, const Slot& w2, const Slot& w3, const Slot& w4) noexcept {
  IvVec left[2][2];
  IvVec right[2][2];
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      left[i][j] = cross(w1.v[i], w2.v[j]);
      right[i][j] = cross(w3.v[i], w4.v[j]);
    }
  }
  Iv sum[5] = {exact(0), exact(0), exact(0), exact(0), exact(0)};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        for (int l = 0; l < 2; ++l)
          sum[i + j + k + l] = sum[i + j + k + l] + dot(left[i][j], right[k][l]);
  const Iv b[5] = {sum[0], divide(sum[1], 4.0), divide(sum[2], 6.0), divide(sum[3], 4.0), sum[4]};
  return range_of(b, 5);
}

/// Upper bound of |w|^2 over the interval.
double norm2_upper(const Slot& w) noexcept {
  const IvVec h = hull(w.v[0], w.v[1]);
  return upper(dot(h, h));
}

/// Upper bound of |w1 x w2|^2 over the interval.
double cross_norm2_upper(const Slot& w1, const Slot& w2) noexcept {
  const IvVec n = cross(hull(w1.v[0], w1.v[1]), hull(w2.v[0], w2.v[1]));
  return upper(dot(n, n));
}

/// Minimum separation and its square (rounded up).
struct Separation {
  double delta = 0.0;
  double delta2 = 0.0;
  explicit Separation(double d) noexcept {
    if (d > 0.0) {  // NaN and negative values mean 0; +inf reports everything
      delta = d;
      delta2 = mul_up(d, d);
    }
  }
  bool zero() const noexcept { return delta == 0.0; }
};

/// True when the function enclosed by r is provably < 0 and its square > delta2 * scale2_hi on
/// the interval, i.e. the signed distance it measures is below -delta everywhere.
bool below_minus_delta(const Range& r, const Separation& s, double scale2_hi) noexcept {
  if (!(r.hi < 0.0)) return false;
  if (s.zero()) return true;
  return mul_down(r.hi, r.hi) > mul_up(s.delta2, scale2_hi);
}

/// True when |function| > delta * sqrt(scale2) on the whole interval (function of one sign).
bool away_from_zero(const Range& r, const Separation& s, double scale2_hi) noexcept {
  if (r.lo > 0.0) return s.zero() || mul_down(r.lo, r.lo) > mul_up(s.delta2, scale2_hi);
  if (r.hi < 0.0) return s.zero() || mul_down(r.hi, r.hi) > mul_up(s.delta2, scale2_hi);
  return false;
}

/// True when the boxes of two groups of moving points over the interval (rigorous bounds of
/// the points at both interval ends; linear motion keeps them inside) are more than delta
/// apart along one axis.
bool boxes_disjoint(const IvVec (*first)[2], int first_count, const IvVec (*second)[2],
                    int second_count, const Separation& s) noexcept {
  for (int axis = 0; axis < 3; ++axis) {
    auto coord = [axis](const IvVec& v) -> Iv { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; };
    double a_lo = INFINITY;
    double a_hi = -INFINITY;
    double b_lo = INFINITY;
    double b_hi = -INFINITY;
    for (int k = 0; k < first_count; ++k) {
      for (int e = 0; e < 2; ++e) {
        a_lo = min_nan(a_lo, lower(coord(first[k][e])));
        a_hi = max_nan(a_hi, upper(coord(first[k][e])));
      }
    }
    for (int k = 0; k < second_count; ++k) {
      for (int e = 0; e < 2; ++e) {
        b_lo = min_nan(b_lo, lower(coord(second[k][e])));
        b_hi = max_nan(b_hi, upper(coord(second[k][e])));
      }
    }
    // Gaps rounded down; a NaN gap compares false and proves nothing.
    const double gap1 = b_lo - a_hi;
    const double gap2 = a_lo - b_hi;
    if (gap1 - (std::fabs(gap1) * kRel + kTiny) > s.delta) return true;
    if (gap2 - (std::fabs(gap2) * kRel + kTiny) > s.delta) return true;
  }
  return false;
}

bool all_finite(const Vec3d* const* points, int count) noexcept {
  for (int i = 0; i < count; ++i)
    for (double x : *points[i])
      if (!std::isfinite(x)) return false;
  return true;
}

enum class Depth { kFilter, kFull };

/// Vertex p against triangle abc. Points: 0 = p, 1 = a, 2 = b, 3 = c.
struct VertexFaceTest {
  const Vec3d* x0[4];
  const Vec3d* x1[4];
  Separation sep;

  bool excluded(double ta, double tb, Depth depth) const noexcept {
    IvVec x[4][2];
    for (int i = 0; i < 4; ++i) {
      x[i][0] = position(*x0[i], *x1[i], ta);
      x[i][1] = ta == tb ? x[i][0] : position(*x0[i], *x1[i], tb);
    }
    if (boxes_disjoint(x, 1, x + 1, 3, sep)) return true;

    const Slot u = difference(x[2], x[1]);  // b - a
    const Slot v = difference(x[3], x[1]);  // c - a
    const Slot w = difference(x[0], x[1]);  // p - a
    const double n2 = sep.zero() ? 0.0 : cross_norm2_upper(u, v);
    if (away_from_zero(trilinear_range(u, v, w), sep, n2)) return true;
    if (depth == Depth::kFilter) return false;

    // Edge planes (through an edge, perpendicular to the triangle): inside needs
    // n . ((b-a) x (p-a)) >= 0 and the two others.
    if (below_minus_delta(quadrilinear_range(u, v, u, w), sep,
                          sep.zero() ? 0.0 : mul_up(n2, norm2_upper(u))))
      return true;
    const Slot cb = difference(x[3], x[2]);
    const Slot pb = difference(x[0], x[2]);
    if (below_minus_delta(quadrilinear_range(u, v, cb, pb), sep,
                          sep.zero() ? 0.0 : mul_up(n2, norm2_upper(cb))))
      return true;
    const Slot ac = difference(x[1], x[3]);
    const Slot pc = difference(x[0], x[3]);
    return below_minus_delta(quadrilinear_range(u, v, ac, pc), sep,
                             sep.zero() ? 0.0 : mul_up(n2, norm2_upper(ac)));
  }
};

/// Edge ab against edge cd. Points: 0 = a, 1 = b, 2 = c, 3 = d.
struct EdgeEdgeTest {
  const Vec3d* x0[4];
  const Vec3d* x1[4];
  Separation sep;

  bool excluded(double ta, double tb, Depth depth) const noexcept {
    IvVec x[4][2];
    for (int i = 0; i < 4; ++i) {
      x[i][0] = position(*x0[i], *x1[i], ta);
      x[i][1] = ta == tb ? x[i][0] : position(*x0[i], *x1[i], tb);
    }
    if (boxes_disjoint(x, 2, x + 2, 2, sep)) return true;

    const Slot ba = difference(x[1], x[0]);
    const Slot dc = difference(x[3], x[2]);
    const Slot ca = difference(x[2], x[0]);
    const double n2 = sep.zero() ? 0.0 : cross_norm2_upper(ba, dc);
    if (away_from_zero(trilinear_range(ba, dc, ca), sep, n2)) return true;
    if (depth == Depth::kFilter) return false;

    // Planes through one edge containing the common normal n = (b-a) x (d-c): the other edge
    // strictly beyond one of them (by delta) cannot touch. With N = |n|^2:
    // h1 = ((c-a) x (d-c)).n, h2 = ((b-c) x (d-c)).n, h1 + h2 = N (closest point on ab at
    // u = h1/N in [0,1]); h3 = ((c-a) x (b-a)).n, h4 = ((b-a) x (d-a)).n, h3 + h4 = N.
    const double dc2 = sep.zero() ? 0.0 : mul_up(n2, norm2_upper(dc));
    if (below_minus_delta(quadrilinear_range(ca, dc, ba, dc), sep, dc2)) return true;
    const Slot bc = difference(x[1], x[2]);
    if (below_minus_delta(quadrilinear_range(bc, dc, ba, dc), sep, dc2)) return true;
    const double ba2 = sep.zero() ? 0.0 : mul_up(n2, norm2_upper(ba));
    if (below_minus_delta(quadrilinear_range(ca, ba, ba, dc), sep, ba2)) return true;
    const Slot da = difference(x[3], x[0]);
    if (below_minus_delta(quadrilinear_range(ba, da, ba, dc), sep, ba2)) return true;

    // Planes containing one edge and turned towards an endpoint of the other (decide parallel
    // and coplanar edges, where n vanishes): m = (b-a) x ((b-a) x (c-a)) puts c at
    // (c-a).m = -|(b-a) x (c-a)|^2 <= 0; if d is strictly on that side too,
    // (d-a).m = ((d-a) x (b-a)).((b-a) x (c-a)) < 0, the plane separates the edges. With a
    // separation: c's distance to line ab, |(b-a) x (c-a)| / |b-a|, and d's, |(d-a).m| / |m|,
    // must both exceed delta. Same with the roles of the edges swapped.
    const Slot ac = difference(x[0], x[2]);
    if (separated_by_edge_plane(da, ba, ca, ba) || separated_by_edge_plane(bc, dc, ac, dc))
      return true;

    // End caps (decide parallel edges): both points of one edge beyond the plane through an
    // endpoint of the other, perpendicular to it.
    const Slot ab = difference(x[0], x[1]);
    const Slot cd = difference(x[2], x[3]);
    const double ab2 = sep.zero() ? 0.0 : norm2_upper(ab);
    const double cd2 = sep.zero() ? 0.0 : norm2_upper(cd);
    const Slot bd = difference(x[1], x[3]);
    // cap at a: (c-a).(a-b) > delta |a-b| and (d-a).(a-b) > delta |a-b|.
    if (above_delta(bilinear_range(ca, ab), ab2) && above_delta(bilinear_range(da, ab), ab2))
      return true;
    // cap at b: (c-b).(b-a), (d-b).(b-a)  ==  (b-c).(a-b), (b-d).(a-b) ... expressed with ab.
    if (above_delta(bilinear_range(bc, ab), ab2) && above_delta(bilinear_range(bd, ab), ab2))
      return true;
    // cap at c: (a-c).(c-d), (b-c).(c-d).
    if (above_delta(bilinear_range(ac, cd), cd2) && above_delta(bilinear_range(bc, cd), cd2))
      return true;
    // cap at d: (a-d).(d-c), (b-d).(d-c) == (d-a).(c-d), (d-b).(c-d).
    return above_delta(bilinear_range(da, cd), cd2) &&
           above_delta(bilinear_range(difference(x[3], x[1]), cd), cd2);
  }

  /// Plane through the edge with direction e (from point o), normal e x (e x (near - o)):
  /// true when far - o and near - o are both strictly (by delta) on the near side.
  bool separated_by_edge_plane(const Slot& far_o, const Slot& e, const Slot& near_o,
                               const Slot& e_again) const noexcept {
    const Range far_side = quadrilinear_range(far_o, e, e_again, near_o);
    if (!(far_side.hi < 0.0)) return false;
    if (sep.zero()) return true;
    const double e2 = norm2_upper(e);
    const Range near2 = quadrilinear_range(e, near_o, e, near_o);  // |e x (near - o)|^2
    if (!(near2.lo > 0.0) || !(mul_down(near2.lo, 1.0) > mul_up(sep.delta2, e2))) return false;
    return mul_down(far_side.hi, far_side.hi) >
           mul_up(sep.delta2, mul_up(e2, cross_norm2_upper(e, near_o)));
  }

  bool above_delta(const Range& r, double scale2_hi) const noexcept {
    return r.lo > 0.0 && (sep.zero() || mul_down(r.lo, r.lo) > mul_up(sep.delta2, scale2_hi));
  }
};

double clamp_tolerance(double tol) noexcept {
  if (!(tol > kMinTolerance)) return kMinTolerance;  // also NaN
  return min_nan(tol, 1.0);
}

template <class Test>
CcdResult run_bisection(const Test& test, const CcdOptions& options) noexcept {
  CcdResult result;
  if (!all_finite(test.x0, 4) || !all_finite(test.x1, 4)) {
    result.outcome = CcdOutcome::kContact;
    result.toi = 0.0;
    return result;
  }
  result.intervals = 1;
  if (!test.excluded(0.0, 0.0, Depth::kFull)) {
    result.outcome = CcdOutcome::kContactAtStart;
    result.toi = 0.0;
    return result;
  }
  const double tol = clamp_tolerance(options.time_tolerance);
  const std::uint32_t max_intervals = std::max<std::uint32_t>(options.max_intervals, 1);
  struct Item {
    double ta, tb;
  };
  Item stack[kStackSize];
  int top = 0;
  stack[top++] = {0.0, 1.0};
  while (top > 0) {
    const Item item = stack[--top];
    ++result.intervals;
    if (test.excluded(item.ta, item.tb, Depth::kFull)) continue;
    const double tm = 0.5 * item.ta + 0.5 * item.tb;
    if (item.tb - item.ta <= tol || result.intervals >= max_intervals || top + 2 > kStackSize ||
        !(tm > item.ta && tm < item.tb)) {
      result.outcome = CcdOutcome::kContact;
      result.toi = item.ta;
      return result;
    }
    stack[top++] = {tm, item.tb};
    stack[top++] = {item.ta, tm};
  }
  return result;
}

}  // namespace

CcdResult vertex_face_ccd(const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0,
                          const Vec3d& p1, const Vec3d& a1, const Vec3d& b1, const Vec3d& c1,
                          const CcdOptions& options) noexcept {
  const VertexFaceTest test{
      {&p0, &a0, &b0, &c0}, {&p1, &a1, &b1, &c1}, Separation(options.min_separation)};
  return run_bisection(test, options);
}

CcdResult edge_edge_ccd(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                        const Vec3d& a1, const Vec3d& b1, const Vec3d& c1, const Vec3d& d1,
                        const CcdOptions& options) noexcept {
  const EdgeEdgeTest test{
      {&a0, &b0, &c0, &d0}, {&a1, &b1, &c1, &d1}, Separation(options.min_separation)};
  return run_bisection(test, options);
}

bool vertex_face_ccd_filter(const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0,
                            const Vec3d& p1, const Vec3d& a1, const Vec3d& b1, const Vec3d& c1,
                            const CcdOptions& options) noexcept {
  const VertexFaceTest test{
      {&p0, &a0, &b0, &c0}, {&p1, &a1, &b1, &c1}, Separation(options.min_separation)};
  if (!all_finite(test.x0, 4) || !all_finite(test.x1, 4)) return true;
  return !test.excluded(0.0, 1.0, Depth::kFilter);
}

bool edge_edge_ccd_filter(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                          const Vec3d& a1, const Vec3d& b1, const Vec3d& c1, const Vec3d& d1,
                          const CcdOptions& options) noexcept {
  const EdgeEdgeTest test{
      {&a0, &b0, &c0, &d0}, {&a1, &b1, &c1, &d1}, Separation(options.min_separation)};
  if (!all_finite(test.x0, 4) || !all_finite(test.x1, 4)) return true;
  return !test.excluded(0.0, 1.0, Depth::kFilter);
}

}  // namespace tetseg
