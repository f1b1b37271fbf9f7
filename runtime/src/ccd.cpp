// Elementary continuous collision tests: vertex-face and edge-edge, linear trajectories.
//
// Method (docs/ccd.md): bisection in time only. On a time interval T every vector used
// (differences of moving points) is affine in t, so every quantity below is a multilinear form
// of such vectors, i.e. a polynomial in t whose Bernstein coefficients on T are averages of
// the form evaluated at the interval ends. Those coefficients are enclosed with rigorous
// interval arithmetic (ccd_interval.hpp); by the convex-hull property they bound the
// polynomial on T. T is excluded when one necessary condition of contact provably fails on
// all of T: swept boxes disjoint, the coplanarity cubic of one sign, the point (the other
// edge) strictly on the outer side of one edge plane, or (exact contact only) an inside
// condition plus a multiple of the coplanarity cubic negative on T (where the cubic vanishes
// the inside condition is then negative). Unexcluded intervals are split, left first, down to
// options.time_tolerance; a leaf that doubles cannot exclude is examined again in
// double-double arithmetic (and, once that was needed, every interval doubles cannot
// exclude); the first leaf still unexcluded is reported with toi = its start, so every time
// before toi was proved contact-free. Below an interval where every inside condition is
// proven positive only the coplanarity cubic can decide, so its sub-intervals test the cubic
// alone, subdivided from that interval's coefficients (exact contact) or recomputed.
// Exact contact also proves contacts (docs/ccd.md, "Exact contacts at the speed of float"):
// certificates at an end of the step in an axis-aligned plane (ccd_plane.hpp), on intervals
// (inside proven and the cubic changing sign; in a plane, the inside conditions), then a jump
// to the crossing or descents in floating point with rigorous error bounds (ccd_bernstein.hpp).

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "ccd_bernstein.hpp"
#include "ccd_interval.hpp"
#include "ccd_plane.hpp"
#include "tetseg/runtime/ccd.hpp"

namespace tetseg {
namespace {

using namespace ccd_detail;

constexpr int kStackSize = 64;

constexpr double kMinTolerance = 0x1p-50;

template <class I>
Vec<I> exact_vec(const Vec3d& x) noexcept {
  return {make<I>(x[0]), make<I>(x[1]), make<I>(x[2])};
}

/// Enclosure of x0 + t (x1 - x0) for an exact time t.
template <class I>
Vec<I> position(const Vec3d& x0, const Vec3d& x1, double t) noexcept {
  if (t == 0.0) return exact_vec<I>(x0);
  if (t == 1.0) return exact_vec<I>(x1);
  const I tt = make<I>(t);
  return {make<I>(x0[0]) + tt * (make<I>(x1[0]) - make<I>(x0[0])),
          make<I>(x0[1]) + tt * (make<I>(x1[1]) - make<I>(x0[1])),
          make<I>(x0[2]) + tt * (make<I>(x1[2]) - make<I>(x0[2]))};
}

/// A vector affine in t over the current interval: enclosures of its values at both ends.
template <class I>
struct Slot {
  Vec<I> v[2];
};

template <class I>
Slot<I> difference(const Vec<I> (&x)[2], const Vec<I> (&y)[2]) noexcept {
  return {{x[0] - y[0], x[1] - y[1]}};
}

/// Bernstein coefficients of a polynomial of degree N on the interval, each multiplied by
/// the binomial coefficient C(N, k) (the sums of the form over the 2^N end choices): same
/// signs as the coefficients, no division.
template <class I, int N>
struct Sums {
  I s[N + 1];
};

template <class I, int N>
Range range_of(const Sums<I, N>& c) noexcept {
  Range r{lower(c.s[0]), upper(c.s[0])};
  for (int i = 1; i <= N; ++i) {
    r.lo = min_nan(r.lo, lower(c.s[i]));
    r.hi = max_nan(r.hi, upper(c.s[i]));
  }
  if (std::isnan(r.lo) || std::isnan(r.hi)) r = {-INFINITY, INFINITY};
  return r;
}

/// Enclosure of the polynomial itself over the interval (sums divided by the binomials).
template <class I, int N>
Range value_range(const Sums<I, N>& c) noexcept {
  static_assert(N >= 2 && N <= 4, "degrees 2..4");
  constexpr double kBinomial[5][5] = {
      {1, 0, 0, 0, 0}, {1, 1, 0, 0, 0}, {1, 2, 1, 0, 0}, {1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};
  Sums<I, N> d = c;
  for (int k = 1; k < N; ++k) d.s[k] = divide(c.s[k], kBinomial[N][k]);
  return range_of(d);
}

/// w1 . w2 (degree 2).
template <class I>
Sums<I, 2> bilinear(const Slot<I>& w1, const Slot<I>& w2) noexcept {
  return {{dot(w1.v[0], w2.v[0]), dot(w1.v[1], w2.v[0]) + dot(w1.v[0], w2.v[1]),
           dot(w1.v[1], w2.v[1])}};
}

/// w1 x w2 (degree 2) as Bernstein sums of vectors: c[k] sums the cross products of the ends
/// i + j = k. Forms that share a cross product compute it once.
template <class I>
struct CrossSums {
  Vec<I> c[3];
};

template <class I>
CrossSums<I> cross_sums(const Slot<I>& w1, const Slot<I>& w2) noexcept {
  const Vec<I> mixed0 = cross(w1.v[0], w2.v[1]);
  const Vec<I> mixed1 = cross(w1.v[1], w2.v[0]);
  return {{cross(w1.v[0], w2.v[0]),
           {mixed0.x + mixed1.x, mixed0.y + mixed1.y, mixed0.z + mixed1.z},
           cross(w1.v[1], w2.v[1])}};
}

/// The 2D cross product of w1 and w2 on the two axes other than `axis` (degree 2).
template <class I>
Sums<I, 2> cross2(const Slot<I>& w1, const Slot<I>& w2, int axis) noexcept {
  auto coord = [](const Vec<I>& v, int k) -> const I& { return k == 0 ? v.x : k == 1 ? v.y : v.z; };
  const int i = (axis + 1) % 3;
  const int j = (axis + 2) % 3;
  auto cross = [&](const Vec<I>& a, const Vec<I>& b) {
    return coord(a, i) * coord(b, j) - coord(a, j) * coord(b, i);
  };
  return {{cross(w1.v[0], w2.v[0]), cross(w1.v[0], w2.v[1]) + cross(w1.v[1], w2.v[0]),
           cross(w1.v[1], w2.v[1])}};
}

/// (w1 x w2) . w3 (degree 3), with n = w1 x w2.
template <class I>
Sums<I, 3> trilinear(const CrossSums<I>& n, const Slot<I>& w3) noexcept {
  return {{dot(n.c[0], w3.v[0]), dot(n.c[0], w3.v[1]) + dot(n.c[1], w3.v[0]),
           dot(n.c[1], w3.v[1]) + dot(n.c[2], w3.v[0]), dot(n.c[2], w3.v[1])}};
}

/// (w1 x w2) . (w3 x w4) (degree 4), with l = w1 x w2 and r = w3 x w4.
template <class I>
Sums<I, 4> quadrilinear(const CrossSums<I>& l, const CrossSums<I>& r) noexcept {
  return {{dot(l.c[0], r.c[0]), dot(l.c[0], r.c[1]) + dot(l.c[1], r.c[0]),
           dot(l.c[0], r.c[2]) + dot(l.c[1], r.c[1]) + dot(l.c[2], r.c[0]),
           dot(l.c[1], r.c[2]) + dot(l.c[2], r.c[1]), dot(l.c[2], r.c[2])}};
}

/// range_of(quadrilinear(l, r)).hi < 0 (the same sums, each proven negative), the end sums
/// (the form's values at the interval ends) first: where they are not negative, as on most
/// calls, the three middle sums are not computed.
template <class I>
bool quadrilinear_negative(const CrossSums<I>& l, const CrossSums<I>& r) noexcept {
  if (!(upper(dot(l.c[0], r.c[0])) < 0.0) || !(upper(dot(l.c[2], r.c[2])) < 0.0)) return false;
  return upper(dot(l.c[0], r.c[1]) + dot(l.c[1], r.c[0])) < 0.0 &&
         upper(dot(l.c[0], r.c[2]) + dot(l.c[1], r.c[1]) + dot(l.c[2], r.c[0])) < 0.0 &&
         upper(dot(l.c[1], r.c[2]) + dot(l.c[2], r.c[1])) < 0.0;
}

/// Mid value of an enclosure, as a double.
inline double mid(Iv a) noexcept {
  return a.m;
}
inline double mid(Dd a) noexcept {
  return a.hi + a.lo;
}

/// True when two of the three polynomials are proven of strictly opposite signs on the whole
/// interval.
template <class I>
bool opposite_signs(const Sums<I, 2>& o1, const Sums<I, 2>& o2, const Sums<I, 2>& o3) noexcept {
  const Range r[3] = {range_of(o1), range_of(o2), range_of(o3)};
  bool positive = false, negative = false;
  for (const Range& x : r) {
    positive = positive || x.lo > 0.0;
    negative = negative || x.hi < 0.0;
  }
  return positive && negative;
}

/// True when e + lambda f < 0 on the whole interval for some lambda (e: an inside condition
/// of degree 4, f: the coplanarity cubic), so that e < 0 wherever f = 0. With Bernstein sums,
/// degree elevation of f is exact: the sums of e + lambda f are E_k + lambda (F_{k-1} + F_k).
/// lambda cancels the change of e across the interval against that of f (any value is valid).
template <class I>
bool negative_where_coplanar(const Sums<I, 4>& e, const Sums<I, 3>& f) noexcept {
  const double df = mid(f.s[3]) - mid(f.s[0]);
  const double lambda = -(mid(e.s[4]) - mid(e.s[0])) / df;
  if (!std::isfinite(lambda)) return false;
  const I l = make<I>(lambda);
  for (int k = 0; k <= 4; ++k) {
    I g = e.s[k];
    if (k >= 1) g = g + l * f.s[k - 1];
    if (k <= 3) g = g + l * f.s[k];
    if (!(upper(g) < 0.0)) return false;
  }
  return true;
}

/// Upper bound of |w|^2 over the interval.
template <class I>
double norm2_upper(const Slot<I>& w) noexcept {
  const IvVec h = hull(w.v[0], w.v[1]);
  return upper(dot(h, h));
}

/// Upper bound of |w1 x w2|^2 over the interval.
template <class I>
double cross_norm2_upper(const Slot<I>& w1, const Slot<I>& w2) noexcept {
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

/// True when the function is provably < 0 on the interval and, with a separation, its
/// square > delta2 * scale2_hi (the signed distance it measures is below -delta).
/// `raw` are the Bernstein sums (sign only); the value range is computed only when needed.
template <class I, int N>
bool below_minus_delta(const Sums<I, N>& raw, const Separation& s, double scale2_hi) noexcept {
  if (s.zero()) return range_of(raw).hi < 0.0;
  const Range r = value_range(raw);
  return r.hi < 0.0 && mul_down(r.hi, r.hi) > mul_up(s.delta2, scale2_hi);
}

/// True when an inside condition g (degree 4) excludes the interval: g below -delta, or (exact
/// contact) g plus a multiple of the coplanarity cubic f negative, so g < 0 wherever f = 0.
/// Tested per condition, right after it is computed: the earliest exclusion skips the rest.
template <class I>
bool outside(const Sums<I, 4>& g, const Sums<I, 3>& f, const Separation& s,
             double scale2_hi) noexcept {
  return below_minus_delta(g, s, scale2_hi) || (s.zero() && negative_where_coplanar(g, f));
}

/// True when the function is provably > 0 on the interval (beyond delta * sqrt(scale2)).
template <class I, int N>
bool above_delta(const Sums<I, N>& raw, const Separation& s, double scale2_hi) noexcept {
  if (s.zero()) return range_of(raw).lo > 0.0;
  const Range r = value_range(raw);
  return r.lo > 0.0 && mul_down(r.lo, r.lo) > mul_up(s.delta2, scale2_hi);
}

/// True when |function| > delta * sqrt(scale2) on the whole interval (one sign).
template <class I, int N>
bool away_from_zero(const Sums<I, N>& raw, const Separation& s, double scale2_hi) noexcept {
  return above_delta(raw, s, scale2_hi) || below_minus_delta(raw, s, scale2_hi);
}

/// True when the boxes of two groups of moving points over the interval (rigorous bounds of
/// the points at both interval ends; linear motion keeps them inside) are more than delta
/// apart along one axis.
template <class I>
bool boxes_disjoint(const Vec<I> (*first)[2], int first_count, const Vec<I> (*second)[2],
                    int second_count, const Separation& s) noexcept {
  for (int axis = 0; axis < 3; ++axis) {
    auto coord = [axis](const Vec<I>& v) -> I { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; };
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

/// Bernstein coefficients of a polynomial of degree 3 or 4 on an interval (the coplanarity
/// cubic, or an inside condition), from its enclosed sums: the midpoints with the largest
/// radius as error bound.
template <int N>
FloatBernstein float_bernstein(const Sums<Iv, N>& sums) noexcept {
  static_assert(N == 3 || N == 4, "degrees 3 and 4");
  constexpr double kBinomial[2][5] = {{1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};
  FloatBernstein p{{}, N, 0.0};
  for (int k = 0; k <= N; ++k) {
    const Iv b = (k == 0 || k == N) ? sums.s[k] : divide(sums.s[k], kBinomial[N - 3][k]);
    p.c[k] = b.m;
    p.err = max_nan(p.err, b.r);
  }
  return p;
}

/// The cubic-first descent's jump (exact contact): on a dyadic interval [ta, tb] where the
/// coplanarity cubic p changes sign, the bisection would halve down to the leaf holding p's
/// root, excluding on the way each half where p is one-signed. Instead, the leaf of that grid
/// (width `leaf`, the bisection's own: a power of two) holding a float estimate of the root is
/// taken at once, when p is proven one-signed on the rest of [ta, tb]: before the leaf
/// (left_part) and after it (right_part), so the leaf holds every root. Its ends, and their
/// local parameters, are grid points: exact. Returns false (the caller halves) when a proof
/// fails: a root near a leaf end, several roots, a bound too wide.
bool root_leaf(const FloatBernstein& p, double ta, double tb, double leaf, double& lo,
               double& hi) noexcept {
  const double width = tb - ta;
  const double local_leaf = leaf / width;  // a power of two: exact
  const double estimate = root_estimate(p, 0.25 * local_leaf);
  const double k = std::floor(estimate / local_leaf);
  const double lambda_lo = k * local_leaf;  // exact: k < 2^53, a power-of-two scale
  const double lambda_hi = lambda_lo + local_leaf;
  if (!(lambda_lo >= 0.0 && lambda_hi <= 1.0)) return false;
  if (lambda_lo > 0.0) {
    const FloatBernstein before = left_part(p, lambda_lo);
    if (!proven_positive(before) && !proven_negative(before)) return false;
  }
  if (lambda_hi < 1.0) {
    const FloatBernstein after = right_part(p, lambda_hi);
    if (!proven_positive(after) && !proven_negative(after)) return false;
  }
  lo = ta + lambda_lo * width;  // grid points: exact
  hi = ta + lambda_hi * width;
  return true;
}

/// Width of the bisection's leaves below a dyadic interval of width `width`: the first halving
/// not above tol.
double leaf_width(double width, double tol) noexcept {
  while (width > tol) width *= 0.5;
  return width;
}

/// How much of a test to run on an interval. kFilter: boxes and the coplanarity cubic (the
/// cheap pre-filter). kFull: every exclusion test. kCoplanarOnly: boxes and the coplanarity
/// cubic, for an interval inside one where every inside condition was proven positive (the
/// point strictly inside the edge planes, the closest-point parameters of both edges strictly
/// inside (0,1)): there the other tests cannot exclude anything (their conditions are proven
/// false), and contact happens exactly where the cubic vanishes. Any subset of the tests is
/// sound (each is a necessary condition of contact); this one only drops useless work.
/// kOpenCondition (exact contact, four points in one plane): below an interval certified with
/// one inside condition open, that condition alone decides (subdivided, never recomputed).
/// kCubicFirst (exact contact): below an interval where the coplanarity cubic changes sign,
/// the subdivided cubic excludes sub-intervals, and a sub-interval it cannot exclude is given
/// the full check only once the cubic no longer changes sign on it or it is a leaf (the
/// crossing is isolated first; the inside conditions are then tested once, near it).
enum class Depth { kFilter, kFull, kCoplanarOnly, kOpenCondition, kCubicFirst };

/// Outcome of one interval: excluded, or open (with `inside` when every inside condition is
/// proven strictly positive on it, so that its sub-intervals need only kCoplanarOnly).
/// Exact contact only, a positive certificate: `certified` when a contact certainly exists in
/// the interval, `contact_at_start` when its start is a contact time.
struct IntervalOutcome {
  bool excluded = false;
  bool inside = false;
  bool certified = false;
  bool contact_at_start = false;
  /// Certified in the plane with one inside condition open: on sub-intervals, contact happens
  /// exactly where that condition is >= 0 (the others are proven positive).
  bool open_condition = false;
  /// Exact contact, a check given a leaf width: the coplanarity cubic has its only root on the
  /// interval in the leaf [leaf_lo, leaf_hi] (root_leaf); nothing else was checked.
  bool to_leaf = false;
  double leaf_lo = 0.0, leaf_hi = 0.0;
};

/// True when every Bernstein sum is proven strictly positive (the polynomial > 0 on T).
template <class I, int N>
bool positive(const Sums<I, N>& raw) noexcept {
  return range_of(raw).lo > 0.0;
}

/// True when the polynomial is proven to take both signs on T: its values at the ends (the
/// first and last Bernstein sums) are of strictly opposite signs, so it has a root in T.
template <class I, int N>
bool sign_change(const Sums<I, N>& raw) noexcept {
  return (upper(raw.s[0]) < 0.0 && lower(raw.s[N]) > 0.0) ||
         (lower(raw.s[0]) > 0.0 && upper(raw.s[N]) < 0.0);
}

/// The outcome sending a check to the leaf holding the coplanarity cubic's only root on
/// [ta, tb] (root_leaf), when there is one: `to_leaf` set, else nothing decided.
inline IntervalOutcome crossing_leaf(const Sums<Iv, 3>& f, double ta, double tb,
                                     double leaf) noexcept {
  IntervalOutcome out{};
  out.to_leaf =
      sign_change(f) && root_leaf(float_bernstein(f), ta, tb, leaf, out.leaf_lo, out.leaf_hi);
  return out;
}

/// Positive certificate of an open interval (exact contact), from the coplanarity cubic f and
/// the inside conditions g[0..count) (vertex-face: the three edge-plane quartics; edge-edge:
/// h1..h4), whose joint non-negativity on the plane of the four points means contact (with
/// the triangle non-degenerate, the edges not parallel: implied below by a proven-positive
/// condition, as A e_ab = ... and h1 + h2 = h3 + h4 = |n|^2). `in_plane`: the four points stay
/// in one plane for the whole step (f vanishes identically).
///  - every condition proven positive on T and f changing sign on T: contact at f's root;
///  - in the plane, every condition positive on T: every time of T is a contact (its start);
///  - in the plane, all conditions but one positive on T and that one positive at an end of
///    T: contact at that end (and `open_condition`, its sums copied to *open_condition).
template <class I, int N>
IntervalOutcome certify(const Sums<I, 3>& f, const Sums<I, 4>* const* conditions, bool in_plane,
                        bool inside, Sums<I, 4>* open_condition) noexcept {
  IntervalOutcome out{false, inside, false, false};
  if (inside) {
    out.contact_at_start = in_plane;
    out.certified = in_plane || sign_change(f);
    return out;
  }
  if (!in_plane) return out;
  int open = -1;
  for (int k = 0; k < N; ++k) {
    if (positive(*conditions[k])) continue;
    if (open >= 0) return out;
    open = k;
  }
  const Sums<I, 4>& g = *conditions[open];
  out.contact_at_start = lower(g.s[0]) > 0.0;
  out.certified = out.contact_at_start || lower(g.s[4]) > 0.0;
  out.open_condition = out.certified;
  if (out.certified && open_condition != nullptr) *open_condition = g;
  return out;
}

/// The four points of a query at the ends of the time interval [ta, tb]: x[i][0] at ta,
/// x[i][1] at tb.
template <class I>
void positions_at(const Vec3d* const x0[4], const Vec3d* const x1[4], double ta, double tb,
                  Vec<I> (&x)[4][2]) noexcept {
  for (int i = 0; i < 4; ++i) {
    x[i][0] = position<I>(*x0[i], *x1[i], ta);
    x[i][1] = ta == tb ? x[i][0] : position<I>(*x0[i], *x1[i], tb);
  }
}

/// Vertex p against triangle abc. Points: 0 = p, 1 = a, 2 = b, 3 = c.
struct VertexFaceTest {
  const Vec3d* x0[4];
  const Vec3d* x1[4];
  Separation sep;
  /// The axis orthogonal to a plane the four points stay in for the whole step, or -1.
  int plane_axis = axis_plane(x0, x1);

  /// `leaf` > 0 (exact contact, doubles): a crossing of the coplanarity cubic goes to its
  /// root's leaf of that width (crossing_leaf) before the inside conditions are computed.
  template <class I>
  IntervalOutcome check(double ta, double tb, Depth depth, Sums<I, 3>* coplanarity = nullptr,
                        Sums<I, 4>* open_condition = nullptr, double leaf = 0.0) const noexcept {
    Vec<I> x[4][2];
    positions_at<I>(x0, x1, ta, tb, x);
    if (boxes_disjoint<I>(x, 1, x + 1, 3, sep)) return {true, false};

    const Slot<I> u = difference(x[2], x[1]);  // b - a
    const Slot<I> v = difference(x[3], x[1]);  // c - a
    const Slot<I> w = difference(x[0], x[1]);  // p - a
    const double n2 = sep.zero() ? 0.0 : cross_norm2_upper(u, v);
    const CrossSums<I> n = cross_sums(u, v);
    const Sums<I, 3> f = trilinear(n, w);
    if (coplanarity != nullptr) *coplanarity = f;
    if (away_from_zero(f, sep, n2)) return {true, false};
    if (depth != Depth::kFull) return {false, depth == Depth::kCoplanarOnly};
    if constexpr (std::is_same_v<I, Iv>) {
      if (leaf > 0.0) {
        const IntervalOutcome jump = crossing_leaf(f, ta, tb, leaf);
        if (jump.to_leaf) return jump;
      }
    }

    const Slot<I> cb = difference(x[3], x[2]);
    const Slot<I> pb = difference(x[0], x[2]);
    const Slot<I> ac = difference(x[1], x[3]);
    const Slot<I> pc = difference(x[0], x[3]);
    // In an axis-aligned plane for the whole step (exact contact): p is in the closed
    // triangle only if no two of its 2D orientations against the edges have strictly
    // opposite signs (inside a proper triangle they share the triangle's sign; on a
    // degenerate one, a segment or a point, they all vanish). This also excludes the times
    // when the triangle degenerates, where the edge-plane conditions below all vanish.
    if (plane_axis >= 0 && sep.zero() &&
        opposite_signs(cross2(u, w, plane_axis), cross2(cb, pb, plane_axis),
                       cross2(ac, pc, plane_axis)))
      return {true, false};

    // Edge planes (through an edge, perpendicular to the triangle): inside needs
    // n . ((b-a) x (p-a)) >= 0 and the two others.
    const Sums<I, 4> e_ab = quadrilinear(n, cross_sums(u, w));
    if (outside(e_ab, f, sep, sep.zero() ? 0.0 : mul_up(n2, norm2_upper(u)))) return {true, false};
    const Sums<I, 4> e_bc = quadrilinear(n, cross_sums(cb, pb));
    if (outside(e_bc, f, sep, sep.zero() ? 0.0 : mul_up(n2, norm2_upper(cb)))) return {true, false};
    const Sums<I, 4> e_ca = quadrilinear(n, cross_sums(ac, pc));
    if (outside(e_ca, f, sep, sep.zero() ? 0.0 : mul_up(n2, norm2_upper(ac)))) return {true, false};
    const bool inside = positive(e_ab) && positive(e_bc) && positive(e_ca);
    if (!sep.zero()) return {false, inside};
    const Sums<I, 4>* const conditions[3] = {&e_ab, &e_bc, &e_ca};
    return certify<I, 3>(f, conditions, plane_axis >= 0, inside, open_condition);
  }

  /// Contact at t = 0 (at_end false) or t = 1 (true) when the four points are then in one
  /// axis-aligned plane (ccd_plane.hpp); unknown otherwise.
  PlaneContact contact_at(bool at_end) const noexcept {
    const Vec3d* const* x = at_end ? x1 : x0;
    const int axis = shared_axis(x);
    return axis < 0 ? PlaneContact::kUnknown : vertex_triangle_2d(*x[0], *x[1], *x[2], *x[3], axis);
  }
};

/// Edge ab against edge cd. Points: 0 = a, 1 = b, 2 = c, 3 = d.
struct EdgeEdgeTest {
  const Vec3d* x0[4];
  const Vec3d* x1[4];
  Separation sep;
  /// The axis orthogonal to a plane the four points stay in for the whole step, or -1.
  int plane_axis = axis_plane(x0, x1);

  /// `leaf` > 0 (exact contact, doubles): a crossing of the coplanarity cubic goes to its
  /// root's leaf of that width (crossing_leaf) before the inside conditions are computed.
  template <class I>
  IntervalOutcome check(double ta, double tb, Depth depth, Sums<I, 3>* coplanarity = nullptr,
                        Sums<I, 4>* open_condition = nullptr, double leaf = 0.0) const noexcept {
    Vec<I> x[4][2];
    positions_at<I>(x0, x1, ta, tb, x);
    if (boxes_disjoint<I>(x, 2, x + 2, 2, sep)) return {true, false};

    const Slot<I> ba = difference(x[1], x[0]);
    const Slot<I> dc = difference(x[3], x[2]);
    const Slot<I> ca = difference(x[2], x[0]);
    const double n2 = sep.zero() ? 0.0 : cross_norm2_upper(ba, dc);
    const CrossSums<I> n = cross_sums(ba, dc);
    const Sums<I, 3> f = trilinear(n, ca);
    if (coplanarity != nullptr) *coplanarity = f;
    if (away_from_zero(f, sep, n2)) return {true, false};
    if (depth != Depth::kFull) return {false, depth == Depth::kCoplanarOnly};
    if constexpr (std::is_same_v<I, Iv>) {
      if (leaf > 0.0) {
        const IntervalOutcome jump = crossing_leaf(f, ta, tb, leaf);
        if (jump.to_leaf) return jump;
      }
    }

    // Planes through one edge containing the common normal n = (b-a) x (d-c): the other edge
    // strictly beyond one of them (by delta) cannot touch. With N = |n|^2:
    // h1 = ((c-a) x (d-c)).n, h2 = ((b-c) x (d-c)).n, h1 + h2 = N (closest point on ab at
    // u = h1/N in [0,1]); h3 = ((c-a) x (b-a)).n, h4 = ((b-a) x (d-a)).n, h3 + h4 = N.
    const double dc2 = sep.zero() ? 0.0 : mul_up(n2, norm2_upper(dc));
    const CrossSums<I> left1 = cross_sums(ca, dc);
    const Sums<I, 4> h1 = quadrilinear(left1, n);
    if (outside(h1, f, sep, dc2)) return {true, false};
    const Slot<I> bc = difference(x[1], x[2]);
    const CrossSums<I> left2 = cross_sums(bc, dc);
    const Sums<I, 4> h2 = quadrilinear(left2, n);
    if (outside(h2, f, sep, dc2)) return {true, false};
    const double ba2 = sep.zero() ? 0.0 : mul_up(n2, norm2_upper(ba));
    const CrossSums<I> left3 = cross_sums(ca, ba);
    const Sums<I, 4> h3 = quadrilinear(left3, n);
    if (outside(h3, f, sep, ba2)) return {true, false};
    const Slot<I> da = difference(x[3], x[0]);
    const CrossSums<I> left4 = cross_sums(ba, da);
    const Sums<I, 4> h4 = quadrilinear(left4, n);
    if (outside(h4, f, sep, ba2)) return {true, false};

    // Planes containing one edge and turned towards an endpoint of the other (decide parallel
    // and coplanar edges, where n vanishes): m = (b-a) x ((b-a) x (c-a)) puts c at
    // (c-a).m = -|(b-a) x (c-a)|^2 <= 0; if d is strictly on that side too,
    // (d-a).m = ((d-a) x (b-a)).((b-a) x (c-a)) < 0, the plane separates the edges. With a
    // separation: c's distance to line ab, |(b-a) x (c-a)| / |b-a|, and d's, |(d-a).m| / |m|,
    // must both exceed delta. Same with the roles of the edges swapped.
    // (d-a) x (b-a) = left4 negated and (b-a) x (c-a) = left3 negated; (b-c) x (d-c) = left2
    // and (d-c) x (a-c) = left1.
    const Slot<I> ac = difference(x[0], x[2]);
    if (separated_by_edge_plane(left4, left3, ba, ca) ||
        separated_by_edge_plane(left2, left1, dc, ac))
      return {true, false};

    // Both closest-point parameters strictly inside (0,1) on all of T (then |n| > 0): the
    // edges touch exactly where the coplanarity cubic vanishes.
    const bool inside = positive(h1) && positive(h2) && positive(h3) && positive(h4);
    // End caps (decide parallel edges): both points of one edge beyond the plane through an
    // endpoint of the other, perpendicular to it. None can hold where `inside` is proven: then
    // the point q of segment cd closest to line ab (v = h3 / N in (0,1)) projects onto ab at
    // u = h1 / N in (0,1), (q - a).(b - a) = u |b - a|^2, while the cap at a (b) puts c and d,
    // so q, strictly before a (beyond b); the same for the caps at c and d. So they are only
    // evaluated when `inside` is not proven (the outcome is the same, with less work).
    if (!inside) {
      const Slot<I> ab = difference(x[0], x[1]);
      const Slot<I> cd = difference(x[2], x[3]);
      const double ab2 = sep.zero() ? 0.0 : norm2_upper(ab);
      const double cd2 = sep.zero() ? 0.0 : norm2_upper(cd);
      const Slot<I> bd = difference(x[1], x[3]);
      // cap at a: (c-a).(a-b) > delta |a-b| and (d-a).(a-b) > delta |a-b|.
      if (above_delta(bilinear(ca, ab), sep, ab2) && above_delta(bilinear(da, ab), sep, ab2))
        return {true, false};
      // cap at b: (c-b).(b-a), (d-b).(b-a), i.e. (b-c).(a-b), (b-d).(a-b).
      if (above_delta(bilinear(bc, ab), sep, ab2) && above_delta(bilinear(bd, ab), sep, ab2))
        return {true, false};
      // cap at c: (a-c).(c-d), (b-c).(c-d).
      if (above_delta(bilinear(ac, cd), sep, cd2) && above_delta(bilinear(bc, cd), sep, cd2))
        return {true, false};
      // cap at d: (a-d).(d-c), (b-d).(d-c), i.e. (d-a).(c-d), (d-b).(c-d).
      if (above_delta(bilinear(da, cd), sep, cd2) &&
          above_delta(bilinear(difference(x[3], x[1]), cd), sep, cd2))
        return {true, false};
    }
    if (!sep.zero()) return {false, inside};
    const Sums<I, 4>* const conditions[4] = {&h1, &h2, &h3, &h4};
    return certify<I, 4>(f, conditions, plane_axis >= 0, inside, open_condition);
  }

  /// Plane through the edge with direction e (from point o), normal e x (e x (near - o)):
  /// true when far - o and near - o are both strictly (by delta) on the near side.
  /// far_e = (far - o) x e and e_near = e x (near - o), or both negated.
  template <class I>
  bool separated_by_edge_plane(const CrossSums<I>& far_e, const CrossSums<I>& e_near,
                               const Slot<I>& e, const Slot<I>& near_o) const noexcept {
    if (sep.zero()) return quadrilinear_negative(far_e, e_near);
    const Sums<I, 4> far_side = quadrilinear(far_e, e_near);
    const Range far_range = value_range(far_side);
    if (!(far_range.hi < 0.0)) return false;
    const double e2 = norm2_upper(e);
    const Range near2 = value_range(quadrilinear(e_near, e_near));  // |e x (near-o)|^2
    if (!(near2.lo > 0.0) || !(mul_down(near2.lo, 1.0) > mul_up(sep.delta2, e2))) return false;
    return mul_down(far_range.hi, far_range.hi) >
           mul_up(sep.delta2, mul_up(e2, cross_norm2_upper(e, near_o)));
  }

  /// Contact at t = 0 (at_end false) or t = 1 (true) when the four points are then in one
  /// axis-aligned plane (ccd_plane.hpp); unknown otherwise.
  PlaneContact contact_at(bool at_end) const noexcept {
    const Vec3d* const* x = at_end ? x1 : x0;
    const int axis = shared_axis(x);
    return axis < 0 ? PlaneContact::kUnknown : segments_2d(*x[0], *x[1], *x[2], *x[3], axis);
  }
};

double clamp_tolerance(double tol) noexcept {
  if (!(tol > kMinTolerance)) return kMinTolerance;  // also NaN
  return min_nan(tol, 1.0);
}

/// True when the coplanarity cubic f, known to vanish at t = 1, is proven nonzero on [0, 1).
/// f = (1 - t) g with g quadratic; g's Bernstein coefficients on [0, 1] are f's sums
/// s0, s1 / 2, s2 (from (1 - t) B_i^2 = C(2,i) / C(3,i) B_i^3), so one strict sign of those three
/// sums makes g, hence f before t = 1, of one sign.
bool nonzero_before_end(const Sums<Iv, 3>& f) noexcept {
  const Sums<Iv, 2> g{{f.s[0], f.s[1], f.s[2]}};
  const Range r = range_of(g);
  return r.lo > 0.0 || r.hi < 0.0;
}

/// The same when f vanishes at t = 0: f = t g, g's coefficients are s1, s2 / 2, s3.
bool nonzero_after_start(const Sums<Iv, 3>& f) noexcept {
  const Sums<Iv, 2> g{{f.s[1], f.s[2], f.s[3]}};
  const Range r = range_of(g);
  return r.lo > 0.0 || r.hi < 0.0;
}

/// Time of impact for a crossing certified on [ta, tb] (exact contact: the inside proven on
/// it, so contact happens exactly where the coplanarity cubic p vanishes; or in a plane, where
/// the open inside condition p is >= 0, p negative at ta; p of opposite signs at the ends): a
/// time t, about tol / 2 before p's first root, such that p is proven nonzero on [ta, t] (its
/// coefficients there, from one de Casteljau step at the estimated root, are of one sign), rounded
/// down. Everything before ta being contact-free, t is a lower bound of the first contact. -1 when
/// the proof fails (then the caller bisects).
double certified_crossing_time(const FloatBernstein& p, double ta, double tb, double tol) noexcept {
  const double width = tb - ta;
  const double local_tol = tol / width;
  const double lambda = root_estimate(p, 0.25 * local_tol) - 0.5 * local_tol;
  if (!(lambda > 0.0)) return ta;  // the root is within tol of ta
  const FloatBernstein left = left_part(p, lambda);
  if (!proven_positive(left) && !proven_negative(left)) return -1.0;
  const double t = ta + lambda * width;  // two roundings: 2^-51 |t| covers them
  return max_nan(ta, t - std::fabs(t) * 0x1p-51);
}

/// Start of the last leaf of the bisection of [0, 1] down to the tolerance: 1 - 2^-k with
/// 2^-k the first halving not above tol.
double last_leaf_start(double tol) noexcept {
  double width = 1.0;
  while (width > tol) width *= 0.5;
  return 1.0 - width;
}

struct Item {
  double ta, tb;
  /// kFull, or kCoplanarOnly inside an interval with the inside proven. Exact contact only:
  /// then `poly` holds the coplanarity cubic's coefficients on [ta, tb], subdivided from the
  /// interval where the inside was proven, and the test is its sign (no recomputation); or,
  /// kOpenCondition, the open inside condition of an interval certified in the plane
  /// (contact exactly where it is >= 0); or, kCubicFirst, and kFull below an interval checked
  /// (exact contact), the coplanarity cubic subdivided from it, which excludes the interval
  /// when of one sign (degree 0: none).
  Depth depth;
  FloatBernstein poly;
};

template <class Test>
CcdResult run_bisection(const Test& test, const CcdOptions& options) noexcept {
  CcdResult result;
  if (!all_finite(test.x0, 4) || !all_finite(test.x1, 4)) {
    result.outcome = CcdOutcome::kContact;
    result.toi = 0.0;
    return result;
  }
  const bool exact_contact = test.sep.zero();
  // The start t = 0 is tested once the whole step could not be excluded: a step excluded as
  // a whole has no contact at t = 0 either, and most queries end there.
  bool start_tested = false;
  const double tol = clamp_tolerance(options.time_tolerance);
  const std::uint32_t max_intervals = std::max<std::uint32_t>(options.max_intervals, 1);
  Item stack[kStackSize];
  int top = 0;
  stack[top++] = {0.0, 1.0, Depth::kFull, {}};
  // Once a leaf has needed double-double to be excluded, the query is near-degenerate (the
  // primitives graze within rounding of doubles): from then on double-double is tried on
  // every interval doubles cannot exclude, before splitting it.
  bool near_degenerate = false;
  // A contact certainly exists in an interval examined so far (exact contact only). Every
  // interval examined later starts before that contact (everything before an examined
  // interval was proved contact-free), so the first leaf doubles cannot exclude is reported
  // as it is: the double-double stage would only move toi later, never decide the hit.
  bool certified = false;
  auto report = [&](CcdOutcome outcome, double toi) {
    result.outcome = outcome;
    result.toi = toi;
    return result;
  };
  // Plane certificates (exact contact): when the four points start (end) in one axis-aligned
  // plane, contact there is a 2D question (ccd_plane.hpp), and the coplanarity cubic vanishes
  // there. Touching at t = 0 is kContactAtStart at once. Otherwise, if the cubic has no other
  // root in [0, 1] (f = (1 - t) g or t g, g of one sign), contact can only happen at that end:
  // touching at t = 1 is the first contact, reported at the start of the bisection's last
  // leaf (what the bisection reports when the rest of the step is excluded); apart, there is
  // none. Only the boxes and the cubic are computed.
  const PlaneContact at_start = exact_contact ? test.contact_at(false) : PlaneContact::kUnknown;
  if (at_start == PlaneContact::kTouching) {
    result.intervals = 1;
    return report(CcdOutcome::kContactAtStart, 0.0);
  }
  const PlaneContact at_end = exact_contact ? test.contact_at(true) : PlaneContact::kUnknown;
  if (at_start != PlaneContact::kUnknown || at_end != PlaneContact::kUnknown) {
    Sums<Iv, 3> f{};
    result.intervals = 1;
    if (test.template check<Iv>(0.0, 1.0, Depth::kFilter, &f).excluded) return result;
    if (at_end != PlaneContact::kUnknown && nonzero_before_end(f))
      return at_end == PlaneContact::kTouching ? report(CcdOutcome::kContact, last_leaf_start(tol))
                                               : result;
    if (at_start == PlaneContact::kApart && nonzero_after_start(f)) return result;
  }
  const bool contact_at_end = at_end == PlaneContact::kTouching;
  while (top > 0) {
    const Item item = stack[--top];
    ++result.intervals;
    const double tm = 0.5 * item.ta + 0.5 * item.tb;
    const bool leaf = item.tb - item.ta <= tol || result.intervals >= max_intervals ||
                      top + 2 > kStackSize || !(tm > item.ta && tm < item.tb);
    Sums<Iv, 3> f{};
    Sums<Iv, 4> open{};
    IntervalOutcome outcome{};
    bool checked = false;  // outcome from the interval check on [ta, tb]
    // The check this interval gets when it is not decided by a subdivided polynomial alone,
    // and the one the double-double stage repeats.
    const Depth depth = item.depth == Depth::kCoplanarOnly ? Depth::kCoplanarOnly : Depth::kFull;
    if (item.depth == Depth::kOpenCondition) {  // certified parent: contact where poly >= 0
      outcome.excluded = proven_negative(item.poly);
      outcome.certified = outcome.open_condition = true;
      outcome.contact_at_start = start_positive(item.poly);
    } else if (exact_contact && item.depth == Depth::kCoplanarOnly) {  // contact where poly = 0
      outcome.excluded = proven_positive(item.poly) || proven_negative(item.poly);
      outcome.inside = true;
      outcome.certified = proven_sign_change(item.poly);
    } else if ((item.depth == Depth::kCubicFirst || item.poly.degree == 3) &&
               (proven_positive(item.poly) || proven_negative(item.poly))) {
      outcome.excluded = true;
    } else if (item.depth == Depth::kCubicFirst && !leaf && proven_sign_change(item.poly)) {
      // The leaf holding the cubic's only root, checked in full as the bisection would
      // (everything else in [ta, tb] is proven contact-free); else one halving.
      double lo = 0.0, hi = 0.0;
      if (root_leaf(item.poly, item.ta, item.tb, leaf_width(item.tb - item.ta, tol), lo, hi)) {
        ++result.intervals;  // the rest of [ta, tb], excluded
        stack[top++] = {lo, hi, Depth::kFull, {}};
        continue;
      }
      FloatBernstein left{}, right{};
      split_half(item.poly, left, right);
      stack[top++] = {tm, item.tb, Depth::kCubicFirst, right};
      stack[top++] = {item.ta, tm, Depth::kCubicFirst, left};
      continue;
    } else {
      // The whole step first (exact contact): a crossing goes straight to its root's leaf.
      const double leaf = exact_contact && !start_tested ? leaf_width(1.0, tol) : 0.0;
      outcome = test.template check<Iv>(item.ta, item.tb, depth, &f, &open, leaf);
      checked = true;
    }
    if (outcome.to_leaf) {
      // The cubic is proven nonzero at t = 0 (it changes sign on [0, 1]): no contact there.
      start_tested = true;
      certified = contact_at_end;
      stack[top++] = {outcome.leaf_lo, outcome.leaf_hi, Depth::kFull, {}};
      continue;
    }
    if (outcome.excluded) continue;
    if (near_degenerate && !certified && test.template check<Dd>(item.ta, item.tb, depth).excluded)
      continue;
    if (!start_tested) {  // item is [0, 1] and f its coplanarity cubic
      start_tested = true;
      ++result.intervals;
      if (outcome.contact_at_start) return report(CcdOutcome::kContactAtStart, 0.0);
      // Exact contact at t = 0 needs the coplanarity cubic to vanish there; its first sum is
      // its value at t = 0: proven nonzero, the start has no contact (the start check would
      // exclude it on the cubic too).
      const bool start_excluded = exact_contact && (lower(f.s[0]) > 0.0 || upper(f.s[0]) < 0.0);
      if (!start_excluded && !test.template check<Iv>(0.0, 0.0, Depth::kFull).excluded &&
          !(exact_contact && test.template check<Dd>(0.0, 0.0, Depth::kFull).excluded))
        return report(CcdOutcome::kContactAtStart, 0.0);
      certified = contact_at_end;  // a contact at t = 1, after every interval examined
    }
    // The start of the interval is a contact and everything before it is contact-free.
    if (outcome.contact_at_start)
      return report(item.ta == 0.0 ? CcdOutcome::kContactAtStart : CcdOutcome::kContact, item.ta);
    certified = certified || outcome.certified;
    // A certified crossing jumps to its time of impact: of the coplanarity cubic below a
    // proven inside, or of the open inside condition in a plane (contact where it is >= 0;
    // it starts negative here, else contact_at_start) when it changes sign on the interval.
    if (exact_contact && outcome.certified && (outcome.inside || outcome.open_condition)) {
      const FloatBernstein p = !checked                 ? item.poly
                               : outcome.open_condition ? float_bernstein(open)
                                                        : float_bernstein(f);
      if (outcome.inside || proven_sign_change(p)) {
        const double toi = certified_crossing_time(p, item.ta, item.tb, tol);
        if (toi >= 0.0) return report(CcdOutcome::kContact, toi);
      }
    }
    if (leaf) {
      if (exact_contact && !near_degenerate && !certified && result.intervals < max_intervals &&
          test.template check<Dd>(item.ta, item.tb, depth).excluded) {
        near_degenerate = true;
        continue;
      }
      return report(CcdOutcome::kContact, item.ta);
    }
    // Children, exact contact: the open condition of an interval certified in the plane, the
    // coplanarity cubic below an interval with the inside proven or where it changes sign,
    // subdivided; else (and with a minimum separation) the check again.
    Depth child = Depth::kFull;
    FloatBernstein left{}, right{};
    if (outcome.open_condition) {
      child = Depth::kOpenCondition;
      split_half(checked ? float_bernstein(open) : item.poly, left, right);
    } else if (outcome.inside) {
      child = Depth::kCoplanarOnly;
      if (exact_contact) split_half(checked ? float_bernstein(f) : item.poly, left, right);
    } else if (exact_contact && checked) {  // the cubic, subdivided, as a pre-filter
      child = sign_change(f) ? Depth::kCubicFirst : Depth::kFull;
      split_half(float_bernstein(f), left, right);
    }
    stack[top++] = {tm, item.tb, child, right};
    stack[top++] = {item.ta, tm, child, left};
  }
  return result;
}

/// The cheap interval filter over the whole step: false only when contact is excluded.
/// Non-finite input may hit.
template <typename Test>
bool filter_may_hit(const Test& test) noexcept {
  if (!all_finite(test.x0, 4) || !all_finite(test.x1, 4)) return true;
  return !test.template check<Iv>(0.0, 1.0, Depth::kFilter).excluded;
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
  return filter_may_hit(test);
}

bool edge_edge_ccd_filter(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                          const Vec3d& a1, const Vec3d& b1, const Vec3d& c1, const Vec3d& d1,
                          const CcdOptions& options) noexcept {
  const EdgeEdgeTest test{
      {&a0, &b0, &c0, &d0}, {&a1, &b1, &c1, &d1}, Separation(options.min_separation)};
  return filter_may_hit(test);
}

}  // namespace tetseg
