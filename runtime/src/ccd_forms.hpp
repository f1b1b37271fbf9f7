#pragma once
// The interval machinery of the elementary CCD tests (runtime/src/ccd.cpp; docs/ccd.md):
// points moving linearly, enclosed at the ends of a time interval; the multilinear forms of
// their differences (polynomials in t) as enclosed Bernstein sums; and the exclusion tests on
// them (one sign, below -delta, negative where the coplanarity cubic vanishes, swept boxes
// apart). Internal to the runtime.

#include <cmath>
#include <type_traits>

#include "ccd_interval.hpp"
#include "tetseg/runtime/ccd.hpp"

namespace tetseg::ccd_detail {
// Internal linkage: ccd.cpp is the only translation unit, and GCC then inlines these as it
// did when they were part of it (external-linkage inline functions cost 1.5-2 % more
// instructions in the elementary tests, callgrind).
namespace {

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

/// Enclosure of (xi - xj)(t) for every t in the enclosure `t` (xi and xj moving linearly over
/// the step, exact input ends): d0 + t (d1 - d0) with d0, d1 the differences at 0 and 1, in
/// interval arithmetic (the value at each t of the enclosure is inside).
inline IvVec difference_over(const Vec3d& xi0, const Vec3d& xi1, const Vec3d& xj0, const Vec3d& xj1,
                             Iv t) noexcept {
  auto coord = [&](int k) {
    const Iv d0 = exact(xi0[k]) - exact(xj0[k]);
    return d0 + t * ((exact(xi1[k]) - exact(xj1[k])) - d0);
  };
  return {coord(0), coord(1), coord(2)};
}

/// difference_over(xi, xj, t) into a and difference_over(yi, yj, t) into b, bitwise, computed
/// as two lanes where the compiler has them.
inline void difference_over2(const Vec3d& xi0, const Vec3d& xi1, const Vec3d& xj0, const Vec3d& xj1,
                             const Vec3d& yi0, const Vec3d& yi1, const Vec3d& yj0, const Vec3d& yj1,
                             Iv t, IvVec& a, IvVec& b) noexcept {
#if defined(TETSEG_HAVE_LANES2)
  const Iv2 tt = lanes(t, t);
  auto coord = [&](int k) {
    const Iv2 d0 = lanes(exact(xi0[k]), exact(yi0[k])) - lanes(exact(xj0[k]), exact(yj0[k]));
    return d0 +
           tt * ((lanes(exact(xi1[k]), exact(yi1[k])) - lanes(exact(xj1[k]), exact(yj1[k]))) - d0);
  };
  const Vec<Iv2> d{coord(0), coord(1), coord(2)};
  a = lane(d, 0);
  b = lane(d, 1);
#else
  a = difference_over(xi0, xi1, xj0, xj1, t);
  b = difference_over(yi0, yi1, yj0, yj1, t);
#endif
}

/// cross(a, b) into ab and cross(c, d) into cd, bitwise, as two lanes where the compiler has
/// them.
inline void cross2(const IvVec& a, const IvVec& b, const IvVec& c, const IvVec& d, IvVec& ab,
                   IvVec& cd) noexcept {
#if defined(TETSEG_HAVE_LANES2)
  const Vec<Iv2> r = cross(lanes(a, c), lanes(b, d));
  ab = lane(r, 0);
  cd = lane(r, 1);
#else
  ab = cross(a, b);
  cd = cross(c, d);
#endif
}

/// dot(a, b) into ab and dot(c, d) into cd, bitwise, as two lanes where the compiler has them.
inline void dot2(const IvVec& a, const IvVec& b, const IvVec& c, const IvVec& d, Iv& ab,
                 Iv& cd) noexcept {
#if defined(TETSEG_HAVE_LANES2)
  const Iv2 r = dot(lanes(a, c), lanes(b, d));
  ab = lane(r, 0);
  cd = lane(r, 1);
#else
  ab = dot(a, b);
  cd = dot(c, d);
#endif
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
#if defined(TETSEG_HAVE_LANES2)
  if constexpr (std::is_same_v<I, Iv>) {
    // Lanes: (v0 x v0, v1 x v1) and (v0 x v1, v1 x v0), each bitwise the scalar cross.
    const Vec<Iv2> a = lanes(w1.v[0], w1.v[1]);
    const Vec<Iv2> ends = cross(a, lanes(w2.v[0], w2.v[1]));
    const Vec<Iv2> mixed = cross(a, lanes(w2.v[1], w2.v[0]));
    return {{lane(ends, 0),
             {lane(mixed.x, 0) + lane(mixed.x, 1), lane(mixed.y, 0) + lane(mixed.y, 1),
              lane(mixed.z, 0) + lane(mixed.z, 1)},
             lane(ends, 1)}};
  }
#endif
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
#if defined(TETSEG_HAVE_LANES2)
  if constexpr (std::is_same_v<I, Iv>) {
    // Lanes: the end sums (n0 . v0, n2 . v1); the middle ones as (n0 . v1, n1 . v1) +
    // (n1 . v0, n2 . v0), each lane the scalar expression.
    const Iv2 ends = dot(lanes(n.c[0], n.c[2]), lanes(w3.v[0], w3.v[1]));
    const Iv2 middle = dot(lanes(n.c[0], n.c[1]), lanes(w3.v[1], w3.v[1])) +
                       dot(lanes(n.c[1], n.c[2]), lanes(w3.v[0], w3.v[0]));
    return {{lane(ends, 0), lane(middle, 0), lane(middle, 1), lane(ends, 1)}};
  }
#endif
  return {{dot(n.c[0], w3.v[0]), dot(n.c[0], w3.v[1]) + dot(n.c[1], w3.v[0]),
           dot(n.c[1], w3.v[1]) + dot(n.c[2], w3.v[0]), dot(n.c[2], w3.v[1])}};
}

/// (w1 x w2) . (w3 x w4) (degree 4), with l = w1 x w2 and r = w3 x w4.
template <class I>
Sums<I, 4> quadrilinear(const CrossSums<I>& l, const CrossSums<I>& r) noexcept {
#if defined(TETSEG_HAVE_LANES2)
  if constexpr (std::is_same_v<I, Iv>) {
    // Lanes: the end sums (l0 . r0, l2 . r2); (s1, s3) as (l0 . r1, l1 . r2) +
    // (l1 . r0, l2 . r1); s2's first two products, then its third alone.
    const Iv2 ends = dot(lanes(l.c[0], l.c[2]), lanes(r.c[0], r.c[2]));
    const Iv2 odd = dot(lanes(l.c[0], l.c[1]), lanes(r.c[1], r.c[2])) +
                    dot(lanes(l.c[1], l.c[2]), lanes(r.c[0], r.c[1]));
    const Iv2 middle = dot(lanes(l.c[0], l.c[1]), lanes(r.c[2], r.c[1]));
    return {{lane(ends, 0), lane(odd, 0), lane(middle, 0) + lane(middle, 1) + dot(l.c[2], r.c[0]),
             lane(odd, 1), lane(ends, 1)}};
  }
#endif
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

}  // namespace
}  // namespace tetseg::ccd_detail
