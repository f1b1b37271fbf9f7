#pragma once
// Measures of test surfaces computed in the tests themselves (not by the library under test);
// squared_distance_to_triangle is tetseg/testing/point_triangle.hpp's.

#include <algorithm>
#include <cmath>

#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/testing/point_triangle.hpp"

namespace tetseg::test {

/// The diagonal of the bounding box of `s`'s vertices (`s` has at least one vertex).
inline double diagonal_of(const preprocess::TriangleMesh& s) {
  preprocess::Vec3 lo = s.vertices.front(), hi = lo;
  for (const preprocess::Vec3& p : s.vertices)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  return std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

}  // namespace tetseg::test
