#pragma once
// Floating-point Bernstein coefficients with a rigorous running error bound, for the descent
// of the elementary CCD tests below an interval where one polynomial alone decides contact
// (the coplanarity cubic, or in a plane one inside condition). Subdividing in plain doubles
// costs a few additions per level instead of interval operations; the bound keeps every
// decision a proof. Internal to the runtime.

#include <cmath>

namespace tetseg::ccd_detail {

/// Rounding error charged per level of de Casteljau averaging, relative to the largest
/// coefficient magnitude M of the parent: one average 0.5 (a + b) rounds once (the halving is
/// exact), by at most 2^-53 |result| <= 2^-53 M; charged 2^-52 M. tests/runtime/
/// ccd_bernstein_test.cpp shows that an eighth of it is violated.
constexpr double kAverageErrorBound = 0x1p-52;
/// Relative factor rounding the bound's own computation upwards, and an absolute floor that
/// covers underflow of the averages (each loses at most 2^-1075).
constexpr double kBoundRoundUp = 1.0 + 0x1p-49;
constexpr double kBoundFloor = 0x1p-500;

/// Polynomial of degree 3 or 4 on an interval: |c[i] - exact i-th Bernstein coefficient| <= err.
struct FloatBernstein {
  double c[5];
  int degree;
  double err;
};

/// Largest coefficient magnitude (NaN propagates).
inline double max_magnitude(const FloatBernstein& p) noexcept {
  double m = 0.0;
  for (int i = 0; i <= p.degree; ++i) {
    const double a = std::fabs(p.c[i]);
    m = (a > m || a != a) ? a : m;
  }
  return m;
}

/// De Casteljau at the midpoint: the coefficients on both halves, with their error bound.
/// `bound_scale` scales the charged rounding error (tests only; 1 in production).
inline void split_half(const FloatBernstein& p, FloatBernstein& left, FloatBernstein& right,
                       double bound_scale = 1.0) noexcept {
  const int n = p.degree;
  left.degree = right.degree = n;
  double w[5] = {};
  for (int i = 0; i <= n; ++i) w[i] = p.c[i];
  left.c[0] = w[0];
  right.c[n] = w[n];
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i + r <= n; ++i) w[i] = 0.5 * (w[i] + w[i + 1]);
    left.c[r] = w[0];
    right.c[n - r] = w[n - r];
  }
  // Averages of values within M stay within M (up to rounding, covered by the factor).
  const double charged = n * kAverageErrorBound * bound_scale * max_magnitude(p);
  left.err = right.err = (p.err + charged) * kBoundRoundUp + kBoundFloor;
}

/// Rounding error charged per level of de Casteljau at a parameter lambda in [0, 1]
/// (w + lambda (w' - w): the difference, the product and the sum each round once, at most
/// 5 2^-53 M together); charged 3 2^-52 M. The propagated error does not grow: in exact
/// arithmetic each new coefficient is a convex combination of the old ones.
constexpr double kLerpErrorBound = 3 * 0x1p-52;

/// The coefficients on the left part [0, lambda] of the interval (local parameter), with their
/// error bound. `bound_scale` as for split_half.
inline FloatBernstein left_part(const FloatBernstein& p, double lambda,
                                double bound_scale = 1.0) noexcept {
  const int n = p.degree;
  FloatBernstein left{{}, n, 0.0};
  double w[5] = {};
  for (int i = 0; i <= n; ++i) w[i] = p.c[i];
  left.c[0] = w[0];
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i + r <= n; ++i) w[i] = w[i] + lambda * (w[i + 1] - w[i]);
    left.c[r] = w[0];
  }
  const double charged = n * kLerpErrorBound * bound_scale * max_magnitude(p);
  left.err = (p.err + charged) * kBoundRoundUp + kBoundFloor;
  return left;
}

/// The coefficients on the right part [lambda, 1] (local parameter), with their error bound:
/// left_part of the reversed polynomial at 1 - lambda, reversed (the same bound). `lambda` must
/// make 1 - lambda exact (a dyadic grid point, as every caller's); `bound_scale` as for
/// split_half.
inline FloatBernstein right_part(const FloatBernstein& p, double lambda,
                                 double bound_scale = 1.0) noexcept {
  const int n = p.degree;
  FloatBernstein reversed{{}, n, p.err};
  for (int i = 0; i <= n; ++i) reversed.c[i] = p.c[n - i];
  const FloatBernstein part = left_part(reversed, 1.0 - lambda, bound_scale);
  FloatBernstein right{{}, n, part.err};
  for (int i = 0; i <= n; ++i) right.c[i] = part.c[n - i];
  return right;
}

/// Estimate (not a proof) of the first root of the polynomial's midpoint coefficients in
/// [0, 1], when their end values have opposite signs: regula falsi (Illinois) on the power
/// form, stopped when the bracket is narrower than `width`. Returns the bracket's left end.
inline double root_estimate(const FloatBernstein& p, double width) noexcept {
  // Power form a0 + a1 s + ... from the Bernstein form.
  double a[5] = {};
  const int n = p.degree;
  constexpr double kBinomial[5][5] = {
      {1, 0, 0, 0, 0}, {1, 1, 0, 0, 0}, {1, 2, 1, 0, 0}, {1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};
  for (int k = 0; k <= n; ++k) {  // a_k = C(n,k) sum_i (-1)^(k-i) C(k,i) c_i
    double sum = 0.0;
    for (int i = 0; i <= k; ++i) sum += ((k - i) % 2 ? -1.0 : 1.0) * kBinomial[k][i] * p.c[i];
    a[k] = kBinomial[n][k] * sum;
  }
  auto value = [&](double s) {
    double v = a[n];
    for (int k = n - 1; k >= 0; --k) v = v * s + a[k];
    return v;
  };
  double lo = 0.0, hi = 1.0, f_lo = value(lo), f_hi = value(hi);
  int side = 0;
  for (int iteration = 0; iteration < 60 && hi - lo > width; ++iteration) {
    double s = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
    if (!(s > lo && s < hi)) s = 0.5 * (lo + hi);
    const double f_s = value(s);
    if ((f_s < 0.0) == (f_lo < 0.0)) {
      lo = s, f_lo = f_s;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = s, f_hi = f_s;
      if (side == 1) f_lo *= 0.5;
      side = 1;
    }
  }
  return lo;
}

/// Proven signs over the interval (convex hull of the coefficients, each within err). A NaN
/// coefficient or bound proves nothing (the comparisons are false).
inline bool proven_positive(const FloatBernstein& p) noexcept {
  for (int i = 0; i <= p.degree; ++i)
    if (!(p.c[i] > p.err)) return false;
  return true;
}
inline bool proven_negative(const FloatBernstein& p) noexcept {
  for (int i = 0; i <= p.degree; ++i)
    if (!(p.c[i] < -p.err)) return false;
  return true;
}

/// Value at the start (c[0]) or end (c[degree]) of the interval proven positive / negative.
inline bool start_positive(const FloatBernstein& p) noexcept {
  return p.c[0] > p.err;
}

/// The values at the two ends are proven of strictly opposite signs (a root in between).
inline bool proven_sign_change(const FloatBernstein& p) noexcept {
  const double first = p.c[0];
  const double last = p.c[p.degree];
  return (first < -p.err && last > p.err) || (first > p.err && last < -p.err);
}

}  // namespace tetseg::ccd_detail
