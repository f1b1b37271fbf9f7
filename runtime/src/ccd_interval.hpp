#pragma once
// Rigorous midpoint-radius interval arithmetic for the elementary CCD tests (internal).
//
// An Iv {m, r} stands for the closed interval [m - r, m + r] and is guaranteed to contain the
// exact real value of the expression it was computed from, whatever the rounding of the
// operations (round-to-nearest assumed, as everywhere in C++ by default). Each operation adds
// to the radius the propagated radii plus the rounding error of its own midpoint (at most
// 2^-53 |m|, bounded here by 2^-52 |m|), and the radius sum itself is rounded upwards by a
// relative factor 1 + 2^-49 (covers the at most 7 roundings of the radius formula) plus an
// absolute floor kTiny = 2^-500 (covers underflow, which loses at most 2^-1074 per rounding).
// The floor is far above the smallest normal double on purpose: every radius is then at least
// 2^-500, so a product of two radii stays a normal double. With the smallest normal double as
// the floor, exactly degenerate queries (four points in one plane: many quantities exactly 0,
// radii at the floor) multiplied radii into the subnormal range, where x86 arithmetic takes a
// microcode assist per operation (such queries ran 3 times slower). The price: quantities
// below about 1e-150 are not resolved. Non-finite values propagate as NaN/inf and then never
// prove anything (all comparisons used for decisions are false on NaN).

#include <cmath>

#include "lanes2.hpp"

namespace tetseg::ccd_detail {

constexpr double kRel = 0x1p-52;
constexpr double kUp = 1.0 + 0x1p-49;
constexpr double kTiny = 0x1p-500;

struct Iv {
  double m;
  double r;
};

inline Iv exact(double x) noexcept {
  return {x, 0.0};
}

inline Iv operator+(Iv a, Iv b) noexcept {
  const double m = a.m + b.m;
  return {m, (a.r + b.r + kRel * std::fabs(m)) * kUp + kTiny};
}

inline Iv operator-(Iv a, Iv b) noexcept {
  const double m = a.m - b.m;
  return {m, (a.r + b.r + kRel * std::fabs(m)) * kUp + kTiny};
}

inline Iv operator-(Iv a) noexcept {
  return {-a.m, a.r};
}

inline Iv operator*(Iv a, Iv b) noexcept {
  const double m = a.m * b.m;
  return {m, (std::fabs(a.m) * b.r + std::fabs(b.m) * a.r + a.r * b.r + kRel * std::fabs(m)) * kUp +
                 kTiny};
}

/// Division by a positive integer constant k (1..6 here).
inline Iv divide(Iv a, double k) noexcept {
  const double m = a.m / k;
  return {m, (a.r / k + kRel * std::fabs(m)) * kUp + kTiny};
}

/// Minimum / maximum that propagate NaN from either argument (std::fmin drops NaN, and is an
/// out-of-line call without -ffast-math).
inline double min_nan(double a, double b) noexcept {
  return (a < b || a != a) ? a : b;
}
inline double max_nan(double a, double b) noexcept {
  return (a > b || a != a) ? a : b;
}

/// Rounded-down lower end and rounded-up upper end of an interval.
inline double lower(Iv a) noexcept {
  const double x = a.m - a.r;
  return x - (std::fabs(x) * kRel + kTiny);
}
inline double upper(Iv a) noexcept {
  const double x = a.m + a.r;
  return x + (std::fabs(x) * kRel + kTiny);
}

/// Interval hull of two intervals.
inline Iv hull(Iv a, Iv b) noexcept {
  const double lo = min_nan(lower(a), lower(b));
  const double hi = max_nan(upper(a), upper(b));
  const double m = 0.5 * lo + 0.5 * hi;
  return {m, max_nan(hi - m, m - lo) * kUp + kTiny};
}

/// Products of non-negative doubles rounded down / up (for comparisons of squares).
inline double mul_down(double x, double y) noexcept {
  return x * y * (1.0 - 0x1p-50);
}
inline double mul_up(double x, double y) noexcept {
  return x * y * (1.0 + 0x1p-50) + kTiny;
}

// ---------------------------------------------------------------------------------------------
// Double-double midpoint with a double radius: Dd {hi, lo, r} stands for [hi+lo-r, hi+lo+r].
// Sums and products of the midpoints use the double-word algorithms of Joldes, Muller and
// Popescu ("Tight and rigorous error bounds for basic building blocks of double-word
// arithmetic", ACM TOMS 2017): AccurateDWPlusDW (relative error < 3u^2 + 13u^3) and
// DWTimesDW3 (relative error < 4u^2), u = 2^-53. The radius charges 2^-96 |result| per
// operation (more than 1000 u^2, a wide margin over both bounds) plus the propagated radii,
// rounded upwards as for Iv. Used only where doubles cannot decide (near-degenerate leaves).

constexpr double kRelDd = 0x1p-96;

struct Dd {
  double hi;
  double lo;
  double r;
};

inline void two_sum(double a, double b, double& s, double& e) noexcept {
  s = a + b;
  const double bb = s - a;
  e = (a - (s - bb)) + (b - bb);
}
inline void fast_two_sum(double a, double b, double& s, double& e) noexcept {
  s = a + b;
  e = b - (s - a);
}
inline void two_prod(double a, double b, double& p, double& e) noexcept {
  p = a * b;
  e = std::fma(a, b, -p);
}

inline Dd exact_dd(double x) noexcept {
  return {x, 0.0, 0.0};
}

inline Dd operator+(Dd a, Dd b) noexcept {
  double sh, sl, th, tl, vh, vl, zh, zl;
  two_sum(a.hi, b.hi, sh, sl);
  two_sum(a.lo, b.lo, th, tl);
  const double c = sl + th;
  fast_two_sum(sh, c, vh, vl);
  const double w = tl + vl;
  fast_two_sum(vh, w, zh, zl);
  return {zh, zl, (a.r + b.r + kRelDd * std::fabs(zh)) * kUp + kTiny};
}

inline Dd operator-(Dd a) noexcept {
  return {-a.hi, -a.lo, a.r};
}
inline Dd operator-(Dd a, Dd b) noexcept {
  return a + (-b);
}

inline Dd operator*(Dd a, Dd b) noexcept {
  double ch, cl1, zh, zl;
  two_prod(a.hi, b.hi, ch, cl1);
  const double tl0 = a.lo * b.lo;
  const double tl1 = std::fma(a.hi, b.lo, tl0);
  const double cl2 = std::fma(a.lo, b.hi, tl1);
  const double cl3 = cl1 + cl2;
  fast_two_sum(ch, cl3, zh, zl);
  // |a.hi + a.lo| <= |a.hi| (1 + 2^-52): magnitudes bounded through the hi parts.
  const double ma = std::fabs(a.hi) * (1.0 + 0x1p-51);
  const double mb = std::fabs(b.hi) * (1.0 + 0x1p-51);
  return {zh, zl, (ma * b.r + mb * a.r + a.r * b.r + kRelDd * std::fabs(zh)) * kUp + kTiny};
}

/// Division by a small positive integer k: multiplication by a double-double enclosure of
/// 1/k (hi = RN(1/k), lo = RN((1 - k hi) / k) with 1 - k hi exact by fma, radius 2^-100).
inline Dd divide(Dd a, double k) noexcept {
  const double h = 1.0 / k;
  const double l = std::fma(-h, k, 1.0) / k;
  return a * Dd{h, l, 0x1p-100};
}

/// Conversion to a double interval (hi, radius |lo| + r rounded up).
inline Iv to_iv(Dd a) noexcept {
  return {a.hi, (std::fabs(a.lo) + a.r) * kUp + kTiny};
}
inline Iv to_iv(Iv a) noexcept {
  return a;
}

inline double lower(Dd a) noexcept {
  return lower(to_iv(a));
}
inline double upper(Dd a) noexcept {
  return upper(to_iv(a));
}

/// Constructors by type, for templates.
template <class I>
I make(double x) noexcept;
template <>
inline Iv make<Iv>(double x) noexcept {
  return exact(x);
}
template <>
inline Dd make<Dd>(double x) noexcept {
  return exact_dd(x);
}

template <class I>
struct Vec {
  I x, y, z;
};
using IvVec = Vec<Iv>;

template <class I>
inline Vec<I> operator-(const Vec<I>& a, const Vec<I>& b) noexcept {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class I>
inline Vec<I> cross(const Vec<I>& a, const Vec<I>& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class I>
inline I dot(const Vec<I>& a, const Vec<I>& b) noexcept {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class I>
inline IvVec hull(const Vec<I>& a, const Vec<I>& b) noexcept {
  return {hull(to_iv(a.x), to_iv(b.x)), hull(to_iv(a.y), to_iv(b.y)), hull(to_iv(a.z), to_iv(b.z))};
}

#if defined(TETSEG_HAVE_LANES2)
/// Two Iv computed at once (lanes2.hpp): lane i of every operation is bitwise the Iv operation
/// on the lanes i of its operands (the same formulas, the same order). The interval kernels
/// evaluate pairs of independent cross and dot products of a form this way.
struct Iv2 {
  Lanes2 m;
  Lanes2 r;
};
inline Iv2 operator+(Iv2 a, Iv2 b) noexcept {
  const Lanes2 m = a.m + b.m;
  return {m, (a.r + b.r + kRel * magnitude(m)) * kUp + kTiny};
}
inline Iv2 operator-(Iv2 a, Iv2 b) noexcept {
  const Lanes2 m = a.m - b.m;
  return {m, (a.r + b.r + kRel * magnitude(m)) * kUp + kTiny};
}
inline Iv2 operator*(Iv2 a, Iv2 b) noexcept {
  const Lanes2 m = a.m * b.m;
  return {m, (magnitude(a.m) * b.r + magnitude(b.m) * a.r + a.r * b.r + kRel * magnitude(m)) * kUp +
                 kTiny};
}
inline Iv2 lanes(Iv a, Iv b) noexcept {
  return {Lanes2{a.m, b.m}, Lanes2{a.r, b.r}};
}
inline Iv lane(const Iv2& a, int i) noexcept {
  return {a.m[i], a.r[i]};
}
/// The vectors a (lane 0) and b (lane 1).
inline Vec<Iv2> lanes(const Vec<Iv>& a, const Vec<Iv>& b) noexcept {
  return {lanes(a.x, b.x), lanes(a.y, b.y), lanes(a.z, b.z)};
}
inline Vec<Iv> lane(const Vec<Iv2>& a, int i) noexcept {
  return {lane(a.x, i), lane(a.y, i), lane(a.z, i)};
}
#endif

/// Rigorous enclosure [lo, hi] of a real function over a time interval.
struct Range {
  double lo;
  double hi;
};

}  // namespace tetseg::ccd_detail
