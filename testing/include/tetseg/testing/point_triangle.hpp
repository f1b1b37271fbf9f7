#pragma once
// Point-triangle distance computed in the tests themselves (not by the library under test),
// shared by the runtime and preprocess test tiers.

#include <array>

namespace tetseg::test {

/// The squared distance from p to the triangle abc (closest point by Voronoi regions, Ericson,
/// Real-Time Collision Detection 5.1.5): independent of CGAL and of the library.
inline double squared_distance_to_triangle(const std::array<double, 3>& p,
                                           const std::array<double, 3>& a,
                                           const std::array<double, 3>& b,
                                           const std::array<double, 3>& c) {
  using Vec3 = std::array<double, 3>;
  auto minus = [](const Vec3& u, const Vec3& v) {
    return Vec3{u[0] - v[0], u[1] - v[1], u[2] - v[2]};
  };
  auto dot = [](const Vec3& u, const Vec3& v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  auto squared = [&](const Vec3& q) {
    const Vec3 d = minus(p, q);
    return dot(d, d);
  };
  auto along = [](const Vec3& o, const Vec3& e, double t) {
    return Vec3{o[0] + t * e[0], o[1] + t * e[1], o[2] + t * e[2]};
  };
  const Vec3 ab = minus(b, a), ac = minus(c, a), ap = minus(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return squared(a);
  const Vec3 bp = minus(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return squared(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return squared(along(a, ab, d1 / (d1 - d3)));
  const Vec3 cp = minus(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return squared(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return squared(along(a, ac, d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return squared(along(b, minus(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denominator = 1.0 / (va + vb + vc);
  const double v = vb * denominator, w = vc * denominator;
  return squared(
      {a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w});
}

}  // namespace tetseg::test
