// End to end on the paper's shapes: generate_shape -> extract_surface -> compute_charge ->
// equalize -> segment_surface -> choose_detectors. The known answers are geometric: where
// the concave necks of each shape are.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "preprocess/support/segment_invariants.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/segmentation.hpp"
#include "tetseg/preprocess/surface.hpp"

using namespace tetseg::preprocess;

namespace {

struct Result {
  TetMesh mesh;
  Surface surface;
  Segmentation seg;
  std::vector<Detector> detectors;
};

Result run_shape(Shape shape, double size) {
  Result r;
  ShapeOptions shape_options;
  shape_options.size = size;
  r.mesh = generate_shape(shape, shape_options);
  r.surface = extract_surface(r.mesh);
  const ChargeResult charge = compute_charge(r.mesh.nodes, r.surface.triangles, {});
  const std::vector<double> eq = equalize(charge.density, Equalization::kHistogram);
  r.seg = segment_surface(r.mesh.nodes, r.surface, eq, {});
  r.detectors = choose_detectors(r.mesh.nodes, r.surface, r.seg.triangle_cluster,
                                 r.seg.cluster_count, DetectorStrategy::kVisibility);
  // Deterministic.
  const Segmentation again = segment_surface(r.mesh.nodes, r.surface, eq, {});
  CHECK(again.triangle_cluster == r.seg.triangle_cluster);
  CHECK(again.boundary_loops == r.seg.boundary_loops);
  return r;
}

void check_detectors(const Result& r) {
  REQUIRE(r.detectors.size() == r.seg.cluster_count);
  for (const Detector& d : r.detectors) {
    CHECK(std::binary_search(r.surface.interior_nodes.begin(), r.surface.interior_nodes.end(),
                             d.node));
    CHECK(d.rest_positive_fraction >= 0.0f);
    CHECK(d.rest_positive_fraction <= 1.0f);
  }
}

// Total turning angle of a loop around an axis (0 = x, 2 = z), in turns.
double winding_turns(const std::vector<Vec3>& nodes, const std::vector<std::uint32_t>& loop,
                     int axis) {
  const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
  double total = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec3& a = nodes[loop[i]];
    const Vec3& b = nodes[loop[(i + 1) % loop.size()]];
    double d = std::atan2(b[v], b[u]) - std::atan2(a[v], a[u]);
    while (d > M_PI) d -= 2 * M_PI;
    while (d < -M_PI) d += 2 * M_PI;
    total += d;
  }
  return std::abs(total) / (2 * M_PI);
}

std::uint32_t cluster_nearest(const Result& r, const Vec3& p) {
  double best = 1e300;
  std::uint32_t cluster = 0;
  for (std::uint32_t t = 0; t < r.surface.triangles.size(); ++t) {
    double d = 0;
    for (int k = 0; k < 3; ++k) {
      double c = 0;
      for (std::uint32_t v : r.surface.triangles[t]) c += r.mesh.nodes[v][k] / 3.0;
      d += (c - p[k]) * (c - p[k]);
    }
    if (d < best) {
      best = d;
      cluster = r.seg.triangle_cluster[t];
    }
  }
  return cluster;
}

// The visibility strategy never does worse than the paper's node and comes within `slack` of
// the best interior node found by brute force (every interior node, every triangle).
void check_visibility_against_brute_force(const Result& r, double slack) {
  const std::vector<Detector> paper =
      choose_detectors(r.mesh.nodes, r.surface, r.seg.triangle_cluster, r.seg.cluster_count,
                       DetectorStrategy::kNearestCentroid);
  for (std::uint32_t c = 0; c < r.seg.cluster_count; ++c) {
    std::vector<std::uint32_t> ids;
    for (std::uint32_t t = 0; t < r.seg.triangle_cluster.size(); ++t)
      if (r.seg.triangle_cluster[t] == c) ids.push_back(t);
    std::uint32_t best = 0;
    for (std::uint32_t v : r.surface.interior_nodes)
      best = std::max(
          best, count_positive_triangles(r.mesh.nodes, r.surface.triangles, ids, r.mesh.nodes[v]));
    const double oracle = static_cast<double>(best) / static_cast<double>(ids.size());
    CAPTURE(c, oracle, paper[c].rest_positive_fraction, r.detectors[c].rest_positive_fraction);
    CHECK(r.detectors[c].rest_positive_fraction >= paper[c].rest_positive_fraction);
    CHECK(r.detectors[c].rest_positive_fraction >= oracle - slack);
  }
}

}  // namespace

TEST_CASE("A sphere is one cluster", "[segmentation][shapes]") {
  const Result r = run_shape(Shape::kSphere, 0.6);
  tetseg::test::check_segmentation_invariants(r.surface.triangles, r.seg);
  CHECK(r.seg.cluster_count == 1);
  CHECK(r.seg.boundary_loops.empty());
  check_detectors(r);
  CHECK(r.detectors[0].rest_positive_fraction == 1.0f);  // convex: every interior node sees all
}

TEST_CASE("A dumbbell's two necks give two boundaries and three clusters",
          "[segmentation][shapes]") {
  // Balls of radius 0.5 at x = +-0.8, neck of radius 0.2: the concave joints are at
  // |x| = 0.8 - sqrt(0.25 - 0.04) = 0.34 (smoothed by the blend).
  const Result r = run_shape(Shape::kDumbbell, 1.0);
  tetseg::test::check_segmentation_invariants(r.surface.triangles, r.seg);
  REQUIRE(r.seg.boundary_loops.size() == 2);
  CHECK(r.seg.cluster_count == 3);
  int negative = 0, positive = 0;
  for (const auto& loop : r.seg.boundary_loops) {
    double lo = 1e9, hi = -1e9;
    for (std::uint32_t v : loop) {
      lo = std::min(lo, r.mesh.nodes[v][0]);
      hi = std::max(hi, r.mesh.nodes[v][0]);
    }
    CAPTURE(lo, hi);
    if (lo > -0.6 && hi < -0.1) ++negative;
    if (lo > 0.1 && hi < 0.6) ++positive;
    CHECK(winding_turns(r.mesh.nodes, loop, 0) == Approx(1.0).margin(1e-6));  // around the neck
  }
  CHECK(negative == 1);
  CHECK(positive == 1);
  const std::uint32_t left = cluster_nearest(r, {-1.3, 0, 0});
  const std::uint32_t middle = cluster_nearest(r, {0, 0.2, 0});
  const std::uint32_t right = cluster_nearest(r, {1.3, 0, 0});
  CHECK(left != middle);
  CHECK(middle != right);
  CHECK(left != right);
  check_detectors(r);
  check_visibility_against_brute_force(r, 0.01);
}

TEST_CASE("A pawn gets a boundary at its collar and neck", "[segmentation][shapes]") {
  // Collar at z = 1.08 (half height 0.035), head a ball of radius 0.27 at z = 1.38.
  const Result r = run_shape(Shape::kPawn, 1.0);
  tetseg::test::check_segmentation_invariants(r.surface.triangles, r.seg);
  CHECK(r.seg.cluster_count >= 2);
  int at_collar = 0;
  for (const auto& loop : r.seg.boundary_loops) {
    double lo = 1e9, hi = -1e9;
    for (std::uint32_t v : loop) {
      lo = std::min(lo, r.mesh.nodes[v][2]);
      hi = std::max(hi, r.mesh.nodes[v][2]);
    }
    CAPTURE(lo, hi);
    CHECK(winding_turns(r.mesh.nodes, loop, 2) == Approx(1.0).margin(1e-6));  // around the axis
    if (lo > 0.95 && hi < 1.2) ++at_collar;
  }
  CHECK(at_collar >= 1);
  CHECK(cluster_nearest(r, {0, 0, 1.65}) != cluster_nearest(r, {0, 0, 0}));  // head vs base
  check_detectors(r);
  check_visibility_against_brute_force(r, 0.01);
}
