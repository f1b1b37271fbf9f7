#pragma once
/// \file
/// Internal: the few Vec3 operations the preprocessing stages share. Plain double arithmetic,
/// header-only so hot loops (charge_potential.cpp) inline them. Not installed.

#include <cmath>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail {

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

/// det[b - a, c - a, d - a]: six times the signed volume of tet (a, b, c, d), positive when
/// d lies on the side of triangle (a, b, c) that its counter-clockwise normal points to.
inline double tet_det(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return dot(sub(b, a), cross(sub(c, a), sub(d, a)));
}

}  // namespace tetseg::preprocess::detail
