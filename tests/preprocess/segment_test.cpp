// Segmentation on voxel shapes with density fields defined by hand: the known answer is
// where the low-density bands were put.

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "../../preprocess/src/segment_topology.hpp"
#include "preprocess/support/segment_invariants.hpp"
#include "preprocess/support/segment_test_shapes.hpp"
#include "tetseg/preprocess/segmentation.hpp"

using namespace tetseg::preprocess;
using tetseg::test::check_segmentation_invariants;
using tetseg::test::field;
using tetseg::test::make_voxel_shape;
using tetseg::test::triangle_centroid;
using tetseg::test::VoxelShape;

namespace {

// Two 4x4x4 cubes joined by a 2x2 neck along x in [4, 8]; 1728 triangles at s = 2.
VoxelShape dumbbell() {
  return make_voxel_shape(12, 4, 4, 2, [](double x, double y, double z) {
    return x < 4 || x > 8 || (y > 1 && y < 3 && z > 1 && z < 3);
  });
}

// A square ring (genus 1): 6x6x2 with a 2x2 hole.
VoxelShape ring() {
  return make_voxel_shape(
      6, 6, 2, 2, [](double x, double y, double) { return !(x > 2 && x < 4 && y > 2 && y < 4); });
}

std::uint32_t cluster_at(const VoxelShape& shape, const Segmentation& seg,
                         bool (*where)(const Vec3&)) {
  for (std::uint32_t t = 0; t < shape.surface.triangles.size(); ++t)
    if (where(triangle_centroid(shape, t))) return seg.triangle_cluster[t];
  FAIL("no triangle at the probe");
  return 0;
}

bool on_neck_band(const Vec3& c, double lo, double hi) {
  return c[0] > lo && c[0] < hi;
}

}  // namespace

TEST_CASE("A surface without marked triangles is one cluster", "[segmentation]") {
  const VoxelShape cube = make_voxel_shape(3, 3, 3, 2, [](double, double, double) { return true; });
  const Segmentation seg = segment_surface(
      cube.nodes, cube.surface, std::vector<double>(cube.surface.triangles.size(), 0.5), {});
  CHECK(seg.cluster_count == 1);
  CHECK(seg.counts.segments_found == 0);
  CHECK(seg.boundary_loops.empty());
  check_segmentation_invariants(cube.surface.triangles, seg);
}

TEST_CASE("One marked region covering the whole surface separates nothing", "[segmentation]") {
  const VoxelShape shape = dumbbell();
  const std::size_t n = shape.surface.triangles.size();
  SECTION("Every triangle marked gives one segment and one cluster.") {
    const Segmentation seg =
        segment_surface(shape.nodes, shape.surface, std::vector<double>(n, 0.01), {});
    CHECK(seg.counts.segments_found == 1);
    CHECK(seg.counts.boundaries == 0);
    CHECK(seg.cluster_count == 1);
    check_segmentation_invariants(shape.surface.triangles, seg);
  }
  SECTION("Everything but one cube marked leaves one piece: no boundary.") {
    const auto eq = field(shape, [](const Vec3& c) { return c[0] < 3.9 ? 0.5 : 0.01; });
    const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, {});
    CHECK(seg.counts.segments_found == 1);
    CHECK(seg.cluster_count == 1);
    check_segmentation_invariants(shape.surface.triangles, seg);
  }
}

TEST_CASE("Low-density bands at both ends of a dumbbell's neck give three clusters",
          "[segmentation]") {
  const VoxelShape shape = dumbbell();
  const auto eq = field(shape, [](const Vec3& c) {
    return (on_neck_band(c, 4.0 + 1e-9, 5.0) || on_neck_band(c, 7.0, 8.0 - 1e-9)) ? 0.05 : 0.6;
  });
  const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, {});
  check_segmentation_invariants(shape.surface.triangles, seg);
  CHECK(seg.counts.segments_found == 2);
  CHECK(seg.counts.segments_grown == 0);
  CHECK(seg.counts.segments_shrunk == 2);
  REQUIRE(seg.boundary_loops.size() == 2);
  REQUIRE(seg.cluster_count == 3);
  // Each boundary lies in its band and goes once around the neck (perimeter 8).
  int left = 0, right = 0;
  for (std::size_t l = 0; l < 2; ++l) {
    double lo = 1e9, hi = -1e9;
    for (std::uint32_t v : seg.boundary_loops[l]) {
      lo = std::min(lo, shape.nodes[v][0]);
      hi = std::max(hi, shape.nodes[v][0]);
    }
    if (lo >= 4.0 && hi <= 5.0) ++left;
    if (lo >= 7.0 && hi <= 8.0) ++right;
    CHECK(seg.boundary_lengths[l] >= 8.0 - 1e-9);
    CHECK(seg.boundary_lengths[l] <= 8.0 * std::sqrt(2.0) + 1e-9);
  }
  CHECK(left == 1);
  CHECK(right == 1);
  const std::uint32_t a = cluster_at(shape, seg, [](const Vec3& c) { return c[0] < 1; });
  const std::uint32_t b =
      cluster_at(shape, seg, [](const Vec3& c) { return c[0] > 5.6 && c[0] < 6.4; });
  const std::uint32_t d = cluster_at(shape, seg, [](const Vec3& c) { return c[0] > 11; });
  CHECK(a != b);
  CHECK(b != d);
  CHECK(a != d);

  SECTION("Two runs give identical results.") {
    const Segmentation again = segment_surface(shape.nodes, shape.surface, eq, {});
    CHECK(again.triangle_cluster == seg.triangle_cluster);
    CHECK(again.boundary_loops == seg.boundary_loops);
  }
  SECTION("A minimum cluster size above the neck's size keeps only one of the two boundaries.") {
    SegmentationOptions options;
    options.min_cluster_triangles = 300;  // cubes have 736 triangles, the neck at most 256
    const Segmentation fewer = segment_surface(shape.nodes, shape.surface, eq, options);
    check_segmentation_invariants(shape.surface.triangles, fewer);
    CHECK(fewer.counts.segments_shrunk == 2);
    CHECK(fewer.cluster_count == 2);
    CHECK(fewer.boundary_loops.size() == 1);
  }
}

TEST_CASE("A band that almost surrounds the neck grows until it separates", "[segmentation]") {
  const VoxelShape shape = dumbbell();
  // The band misses the neck's top face (z = 3): one contour, it separates nothing yet.
  const auto eq = field(
      shape, [](const Vec3& c) { return (on_neck_band(c, 5.5, 6.5) && c[2] < 2.99) ? 0.05 : 0.6; });
  SECTION("With the default bound the grown segment yields one boundary and two clusters.") {
    const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, {});
    check_segmentation_invariants(shape.surface.triangles, seg);
    CHECK(seg.counts.segments_found == 1);
    CHECK(seg.counts.segments_grown == 1);
    REQUIRE(seg.boundary_loops.size() == 1);
    CHECK(seg.cluster_count == 2);
    // Tightened inside the grown band: the shortest ring around the 2x2 neck, perimeter 8
    // (the untightened contour of the shrunk strip zig-zags and is longer).
    CHECK(seg.boundary_lengths[0] == Approx(8.0));
    for (std::uint32_t v : seg.boundary_loops[0]) {
      CHECK(shape.nodes[v][0] > 4.0);
      CHECK(shape.nodes[v][0] < 8.0);
    }
  }
  SECTION("Growth hitting its bound drops the segment.") {
    SegmentationOptions options;
    options.growth_bound = 0.02;  // 34 triangles: less than the band itself
    const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, options);
    check_segmentation_invariants(shape.surface.triangles, seg);
    CHECK(seg.counts.segments_grown == 0);
    CHECK(seg.boundary_loops.empty());
    CHECK(seg.cluster_count == 1);
  }
  SECTION("A segment not larger than beta is not grown.") {
    SegmentationOptions options;
    options.beta_divisor = 10.0;  // beta = 172 triangles > 48
    const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, options);
    CHECK(seg.counts.segments_grown == 0);
    CHECK(seg.cluster_count == 1);
  }
}

TEST_CASE("A band broken into pieces is joined by growing through marked triangles",
          "[segmentation]") {
  const VoxelShape shape = dumbbell();
  // A band around the neck at x in (5.5, 6.5), broken at the neck's four long edges.
  const auto eq = field(shape, [](const Vec3& c) {
    const bool near_edge = (std::abs(c[1] - 1) < 0.3 || std::abs(c[1] - 3) < 0.3) &&
                           (std::abs(c[2] - 1) < 0.3 || std::abs(c[2] - 3) < 0.3);
    return on_neck_band(c, 5.5, 6.5) && !near_edge ? 0.05 : 0.6;
  });
  SegmentationOptions options;
  options.growth_bound = 0.12;  // 207 triangles: too few for one piece to grow around alone
  SECTION("Growing through the other pieces closes the band within the bound.") {
    const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, options);
    check_segmentation_invariants(shape.surface.triangles, seg);
    CHECK(seg.counts.segments_found == 4);
    CHECK(seg.counts.segments_grown >= 1);
    REQUIRE(seg.boundary_loops.size() == 1);  // one per band, not one per piece
    CHECK(seg.cluster_count == 2);
    for (std::uint32_t v : seg.boundary_loops[0]) {
      CHECK(shape.nodes[v][0] > 4.0);
      CHECK(shape.nodes[v][0] < 8.0);
    }
  }
  SECTION("The paper's growth (neighbours only) hits the bound and finds no boundary.") {
    options.grow_through_marked = false;
    const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, options);
    check_segmentation_invariants(shape.surface.triangles, seg);
    CHECK(seg.counts.segments_grown == 0);
    CHECK(seg.cluster_count == 1);
  }
}

TEST_CASE("A band around a ring's arm has two contours but separates nothing", "[segmentation]") {
  const VoxelShape shape = ring();
  const auto eq = field(
      shape, [](const Vec3& c) { return (c[0] < 2.01 && c[1] > 2.5 && c[1] < 3.5) ? 0.05 : 0.6; });
  // The band really is a closed ring with two contours.
  std::vector<std::uint8_t> in_set(eq.size());
  std::vector<std::uint32_t> set;
  for (std::uint32_t t = 0; t < eq.size(); ++t)
    if (eq[t] < 0.1) {
      in_set[t] = 1;
      set.push_back(t);
    }
  tetseg::preprocess::detail::HalfEdges mesh(shape.surface.triangles);
  CHECK(tetseg::preprocess::detail::trace_contours(mesh, shape.nodes, in_set, set).size() == 2);

  const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, {});
  check_segmentation_invariants(shape.surface.triangles, seg);
  CHECK(seg.counts.segments_found == 1);
  CHECK(seg.counts.segments_grown == 0);
  CHECK(seg.boundary_loops.empty());
  CHECK(seg.cluster_count == 1);
}

TEST_CASE("Contours turn through the outside at pinch vertices", "[segmentation]") {
  const VoxelShape cube = make_voxel_shape(4, 4, 4, 1, [](double, double, double) { return true; });
  // Two bottom-face cells touching at the node (2, 2, 0) only.
  std::vector<std::uint8_t> in_set(cube.surface.triangles.size(), 0);
  std::vector<std::uint32_t> set;
  for (std::uint32_t t = 0; t < cube.surface.triangles.size(); ++t) {
    const Vec3 c = triangle_centroid(cube, t);
    const bool cell_a = c[0] > 1 && c[0] < 2 && c[1] > 1 && c[1] < 2;
    const bool cell_b = c[0] > 2 && c[0] < 3 && c[1] > 2 && c[1] < 3;
    if (c[2] == 0.0 && (cell_a || cell_b)) {
      in_set[t] = 1;
      set.push_back(t);
    }
  }
  REQUIRE(set.size() == 4);
  tetseg::preprocess::detail::HalfEdges mesh(cube.surface.triangles);
  const auto contours = tetseg::preprocess::detail::trace_contours(mesh, cube.nodes, in_set, set);
  REQUIRE(contours.size() == 1);  // one figure-eight around both cells
  CHECK(contours[0].closed);
  CHECK(contours[0].half_edges.size() == 8);
  CHECK(contours[0].length == Approx(8.0));
  const std::uint32_t pinch = 2 + 5 * 2;
  int visits = 0;
  for (std::uint32_t h : contours[0].half_edges) visits += mesh.from(h) == pinch ? 1 : 0;
  CHECK(visits == 2);
  for (std::size_t i = 0; i < 8; ++i)
    CHECK(mesh.to(contours[0].half_edges[i]) == mesh.from(contours[0].half_edges[(i + 1) % 8]));
}

TEST_CASE("Odd input never crashes and still partitions", "[segmentation]") {
  VoxelShape shape = dumbbell();
  auto eq =
      field(shape, [](const Vec3& c) { return on_neck_band(c, 4.0 + 1e-9, 5.0) ? 0.05 : 0.6; });
  SECTION("NaN densities count as unmarked.") {
    eq[0] = std::numeric_limits<double>::quiet_NaN();
    const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, {});
    check_segmentation_invariants(shape.surface.triangles, seg);
    CHECK(seg.cluster_count == 2);
  }
  SECTION("A duplicated triangle (non-manifold edges) is tolerated.") {
    shape.surface.triangles.push_back(shape.surface.triangles[5]);
    eq.push_back(0.6);
    const Segmentation seg = segment_surface(shape.nodes, shape.surface, eq, {});
    CHECK(seg.triangle_cluster.size() == shape.surface.triangles.size());
    for (std::uint32_t c : seg.triangle_cluster) CHECK(c < seg.cluster_count);
  }
  SECTION("A density list of the wrong length is a programming error.") {
    eq.pop_back();
    CHECK_THROWS_AS(segment_surface(shape.nodes, shape.surface, eq, {}), std::invalid_argument);
  }
}
