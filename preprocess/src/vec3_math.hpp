#pragma once
/// \file
/// Internal: the few Vec3 operations the preprocessing stages share. Plain double arithmetic,
/// header-only so hot loops (charge_potential.cpp) inline them. Not installed.

#include <cmath>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail {

constexpr double kPi = 3.14159265358979323846;

inline Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
inline double distance2(const Vec3& a, const Vec3& b) {
  const Vec3 d = sub(a, b);
  return dot(d, d);
}
inline double distance_between(const Vec3& a, const Vec3& b) {
  return std::sqrt(distance2(a, b));
}

/// Solid angle of triangle (a, b, c) seen from p (Van Oosterom and Strackee), signed: positive
/// when p lies on the side its counter-clockwise normal points away from. Summed over a closed,
/// outward surface it is 4 pi inside and 0 outside (the generalised winding number x 4 pi).
inline double solid_angle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 x = sub(a, p), y = sub(b, p), z = sub(c, p);
  const double lx = std::sqrt(dot(x, x)), ly = std::sqrt(dot(y, y)), lz = std::sqrt(dot(z, z));
  const double numerator = dot(x, cross(y, z));
  const double denominator = lx * ly * lz + dot(x, y) * lz + dot(y, z) * lx + dot(z, x) * ly;
  return 2.0 * std::atan2(numerator, denominator);
}

/// Whether a surface triangle of `area` and longest edge `longest` is too thin for the charge
/// solver's panel integrals (charge_potential.cpp), on a surface whose longest edge is
/// `surface_longest`: area at most 1e-12 surface_longest^2 or at most 1e-10 longest^2.
inline bool is_degenerate_panel(double area, double longest, double surface_longest) {
  return !(area > 1e-12 * surface_longest * surface_longest) || !(area > 1e-10 * longest * longest);
}

/// det[b - a, c - a, d - a]: six times the signed volume of tet (a, b, c, d), positive when
/// d lies on the side of triangle (a, b, c) that its counter-clockwise normal points to.
inline double tet_det(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return dot(sub(b, a), cross(sub(c, a), sub(d, a)));
}

}  // namespace tetseg::preprocess::detail
