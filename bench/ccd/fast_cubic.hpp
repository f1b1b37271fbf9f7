#pragma once
/// \file
/// A fast, NON-conservative elementary CCD used only as a baseline in the benchmark
/// (`tetseg-ccd queries --method fast-cubic`): solve the coplanarity cubic in double with
/// epsilons, then test inside with an epsilon at each root. It misses contacts (false
/// negatives) by design; never use it for collision handling.

#include <algorithm>
#include <array>
#include <cmath>

namespace tetseg::tools::fast_cubic {

using V = std::array<double, 3>;

inline V sub(const V& a, const V& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline V lerp(const V& a, const V& b, double t) {
  return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
}
inline V cross(const V& a, const V& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const V& a, const V& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Real roots in [0,1] of the cubic with Bernstein coefficients b (sorted); returns count.
/// Monotone pieces between the derivative's roots, bisection with 60 steps in each.
inline int cubic_roots(const std::array<double, 4>& b, double (&roots)[3]) {
  const double c0 = b[0];
  const double c1 = 3 * (b[1] - b[0]);
  const double c2 = 3 * (b[2] - 2 * b[1] + b[0]);
  const double c3 = b[3] - 3 * b[2] + 3 * b[1] - b[0];
  auto f = [&](double t) { return ((c3 * t + c2) * t + c1) * t + c0; };
  double cuts[4] = {0, 0, 0, 1};
  int n_cuts = 1;
  // Derivative 3 c3 t^2 + 2 c2 t + c1.
  const double qa = 3 * c3, qb = 2 * c2, qc = c1;
  if (std::fabs(qa) > 1e-300) {
    const double disc = qb * qb - 4 * qa * qc;
    if (disc > 0) {
      const double s = std::sqrt(disc);
      double r1 = (-qb - s) / (2 * qa), r2 = (-qb + s) / (2 * qa);
      if (r1 > r2) std::swap(r1, r2);
      if (r1 > 0 && r1 < 1) cuts[n_cuts++] = r1;
      if (r2 > 0 && r2 < 1) cuts[n_cuts++] = r2;
    }
  } else if (std::fabs(qb) > 1e-300) {
    const double r = -qc / qb;
    if (r > 0 && r < 1) cuts[n_cuts++] = r;
  }
  cuts[n_cuts++] = 1;
  int count = 0;
  for (int i = 0; i + 1 < n_cuts; ++i) {
    double lo = cuts[i], hi = cuts[i + 1];
    double flo = f(lo), fhi = f(hi);
    if (flo == 0) {
      if (count == 0 || roots[count - 1] != lo) roots[count++] = lo;
      continue;
    }
    if ((flo > 0) == (fhi > 0) && fhi != 0) continue;
    for (int k = 0; k < 60; ++k) {
      const double mid = 0.5 * (lo + hi);
      const double fm = f(mid);
      if ((fm > 0) == (flo > 0))
        lo = mid, flo = fm;
      else
        hi = mid;
    }
    if (count < 3) roots[count++] = hi;
  }
  return count;
}

/// Bernstein coefficients of (u x v) . w for vectors moving linearly.
inline std::array<double, 4> triple_bernstein(const V& u0, const V& v0, const V& w0, const V& u1,
                                              const V& v1, const V& w1) {
  auto d = [](const V& a, const V& b, const V& c) { return dot(cross(a, b), c); };
  return {d(u0, v0, w0), (d(u1, v0, w0) + d(u0, v1, w0) + d(u0, v0, w1)) / 3,
          (d(u1, v1, w0) + d(u1, v0, w1) + d(u0, v1, w1)) / 3, d(u1, v1, w1)};
}

inline bool vertex_face(const V& p0, const V& a0, const V& b0, const V& c0, const V& p1,
                        const V& a1, const V& b1, const V& c1, double& toi) {
  const double eps = 1e-8;
  const auto b = triple_bernstein(sub(b0, a0), sub(c0, a0), sub(p0, a0), sub(b1, a1), sub(c1, a1),
                                  sub(p1, a1));
  double roots[3];
  int n = cubic_roots(b, roots);
  const double scale =
      std::max({std::fabs(b[0]), std::fabs(b[1]), std::fabs(b[2]), std::fabs(b[3])});
  if (scale < 1e-30) {  // coplanar for the whole step: sample
    roots[0] = 0, roots[1] = 0.5, roots[2] = 1, n = 3;
  }
  for (int i = 0; i < n; ++i) {
    const double t = roots[i];
    const V p = lerp(p0, p1, t), a = lerp(a0, a1, t), bb = lerp(b0, b1, t), c = lerp(c0, c1, t);
    const V n_ = cross(sub(bb, a), sub(c, a));
    const double nn = dot(n_, n_);
    if (nn < 1e-300) continue;
    const double w_a = dot(cross(sub(bb, p), sub(c, p)), n_) / nn;
    const double w_b = dot(cross(sub(c, p), sub(a, p)), n_) / nn;
    const double w_c = 1 - w_a - w_b;
    if (w_a >= -eps && w_b >= -eps && w_c >= -eps) {
      toi = t;
      return true;
    }
  }
  return false;
}

inline bool edge_edge(const V& a0, const V& b0, const V& c0, const V& d0, const V& a1, const V& b1,
                      const V& c1, const V& d1, double& toi) {
  const double eps = 1e-8;
  const auto b = triple_bernstein(sub(b0, a0), sub(d0, c0), sub(c0, a0), sub(b1, a1), sub(d1, c1),
                                  sub(c1, a1));
  double roots[3];
  int n = cubic_roots(b, roots);
  const double scale =
      std::max({std::fabs(b[0]), std::fabs(b[1]), std::fabs(b[2]), std::fabs(b[3])});
  if (scale < 1e-30) roots[0] = 0, roots[1] = 0.5, roots[2] = 1, n = 3;
  for (int i = 0; i < n; ++i) {
    const double t = roots[i];
    const V a = lerp(a0, a1, t), bb = lerp(b0, b1, t), c = lerp(c0, c1, t), d = lerp(d0, d1, t);
    const V n_ = cross(sub(bb, a), sub(d, c));
    const double nn = dot(n_, n_);
    if (nn < 1e-300) continue;
    const double u = dot(cross(sub(c, a), sub(d, c)), n_) / nn;
    const double v = dot(cross(sub(c, a), sub(bb, a)), n_) / nn;
    if (u >= -eps && u <= 1 + eps && v >= -eps && v <= 1 + eps) {
      toi = t;
      return true;
    }
  }
  return false;
}

}  // namespace tetseg::tools::fast_cubic
