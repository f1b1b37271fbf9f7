#pragma once
// Rigorous midpoint-radius interval arithmetic for the elementary CCD tests (internal).
//
// An Iv {m, r} stands for the closed interval [m - r, m + r] and is guaranteed to contain the
// exact real value of the expression it was computed from, whatever the rounding of the
// operations (round-to-nearest assumed, as everywhere in C++ by default). Each operation adds
// to the radius the propagated radii plus the rounding error of its own midpoint (at most
// 2^-53 |m|, bounded here by 2^-52 |m|), and the radius sum itself is rounded upwards by a
// relative factor 1 + 2^-49 (covers the at most 7 roundings of the radius formula) plus the
// smallest normal double (covers underflow). Non-finite values propagate as NaN/inf and then
// never prove anything (all comparisons used for decisions are false on NaN).

#include <cmath>
#include <limits>

namespace tetseg::ccd_detail {

constexpr double kRel = 0x1p-52;
constexpr double kUp = 1.0 + 0x1p-49;
constexpr double kTiny = std::numeric_limits<double>::min();

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
inline double min_nan(double a, double b) noexcept { return (a < b || a != a) ? a : b; }
inline double max_nan(double a, double b) noexcept { return (a > b || a != a) ? a : b; }

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

struct IvVec {
  Iv x, y, z;
};

inline IvVec operator-(const IvVec& a, const IvVec& b) noexcept {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline IvVec cross(const IvVec& a, const IvVec& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Iv dot(const IvVec& a, const IvVec& b) noexcept {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline IvVec hull(const IvVec& a, const IvVec& b) noexcept {
  return {hull(a.x, b.x), hull(a.y, b.y), hull(a.z, b.z)};
}

/// Rigorous enclosure [lo, hi] of a real function over a time interval.
struct Range {
  double lo;
  double hi;
};

}  // namespace tetseg::ccd_detail
