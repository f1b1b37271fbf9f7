// The deviation figure (two-sided approximate Hausdorff distance) that every surface build
// reports and that auto's far-patch rule and the deviation retries decide on: against the
// analytic distance between two spheres, and reproducible whatever state CGAL's default random
// generator is in (CGAL 5.5 samples edges with it, seeded from the clock).

#include <CGAL/Random.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "../../preprocess/src/repair_internal.hpp"
#include "tetseg/testing/charge_shapes.hpp"

namespace {

using tetseg::preprocess::detail::hausdorff_distances;
using tetseg::test::ellipsoid;
using tetseg::test::icosphere;

// The smallest distance from the origin to the plane of a face of `mesh`.
double smallest_plane_distance(const tetseg::preprocess::TriangleMesh& mesh) {
  double smallest = 1e300;
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.vertices[t[0]];
    const auto& b = mesh.vertices[t[1]];
    const auto& c = mesh.vertices[t[2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                         u[0] * v[1] - u[1] * v[0]};
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    smallest = std::min(smallest, std::abs(n[0] * a[0] + n[1] * a[1] + n[2] * a[2]) / length);
  }
  return smallest;
}

}  // namespace

TEST_CASE("deviation between two spheres is their radius difference, both ways", "[deviation]") {
  const auto inner = icosphere(4, 1.0);
  const auto outer = icosphere(3, 1.1);
  // Both are convex and centred at the origin, vertices on their spheres, so every surface
  // point of one lies between its faces' smallest plane distance and its radius. The distance
  // from a point of the inner surface to the outer one lies between (outer's smallest plane
  // distance - 1) and (1.1 - the point's radius); from a point of the outer surface to the
  // inner one, between (the point's radius - 1) and (1.1 - inner's smallest plane distance).
  const double inner_min = smallest_plane_distance(inner);
  const double outer_min = smallest_plane_distance(outer);
  const auto [inner_to_outer, outer_to_inner] = hausdorff_distances(inner, outer);
  CHECK(inner_to_outer >= outer_min - 1.0 - 1e-9);
  CHECK(inner_to_outer <= 1.1 - inner_min + 1e-9);
  CHECK(outer_to_inner >= outer_min - 1.0 - 1e-9);
  CHECK(outer_to_inner <= 1.1 - inner_min + 1e-9);
  // The outer vertices are sampled and lie 0.1 beyond every point of the inner surface.
  CHECK(outer_to_inner >= 0.1 - 1e-9);
}

TEST_CASE("deviation does not depend on CGAL's default random generator", "[deviation]") {
  const auto sphere = icosphere(3, 1.0);
  const auto squashed = ellipsoid(2, 1.08, 0.97, 0.9);
  CGAL::get_default_random() = CGAL::Random(7);
  const auto first = hausdorff_distances(sphere, squashed);
  CGAL::get_default_random() = CGAL::Random(123457);
  const auto second = hausdorff_distances(sphere, squashed);
  CHECK(first.first == second.first);
  CHECK(first.second == second.second);
  CHECK(first.first > 0.0);
}
