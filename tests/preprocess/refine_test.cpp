// Cluster refinement: the minimum cut against exhaustive enumeration, and refine_clusters on
// voxel solids whose star-shaped parts are known (a U splits into its convex arms, two halves
// of a box merge), checked against brute-force visibility over every interior node.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "../../preprocess/src/min_cut.hpp"
#include "preprocess/support/segment_invariants.hpp"
#include "preprocess/support/segment_test_shapes.hpp"
#include "tetseg/preprocess/segmentation.hpp"

using namespace tetseg::preprocess;
using tetseg::test::check_segmentation_invariants;
using tetseg::test::make_voxel_shape;
using tetseg::test::VoxelShape;

namespace {

struct Arc {
  std::uint32_t u, v;
  double capacity;
};

/// Cheapest s-t cut by enumerating every side assignment of the other vertices.
double brute_min_cut(std::uint32_t n, const std::vector<Arc>& arcs, std::uint32_t s,
                     std::uint32_t t) {
  double best = 1e300;
  for (std::uint32_t mask = 0; mask < (1u << n); ++mask) {
    if (!(mask >> s & 1) || (mask >> t & 1)) continue;  // s on the source side, t not
    double cut = 0.0;
    for (const Arc& a : arcs)
      if ((mask >> a.u & 1) && !(mask >> a.v & 1)) cut += a.capacity;
    best = std::min(best, cut);
  }
  return best;
}

/// Best share of `ids` positive from any interior node (exhaustive).
double brute_visibility(const VoxelShape& shape, const std::vector<std::uint32_t>& ids) {
  std::uint32_t best = 0;
  for (std::uint32_t node : shape.surface.interior_nodes)
    best = std::max(best, count_positive_triangles(shape.nodes, shape.surface.triangles, ids,
                                                   shape.nodes[node]));
  return static_cast<double>(best) / static_cast<double>(ids.size());
}

std::vector<std::vector<std::uint32_t>> members(const Segmentation& seg) {
  std::vector<std::vector<std::uint32_t>> out(seg.cluster_count);
  for (std::uint32_t t = 0; t < seg.triangle_cluster.size(); ++t)
    out[seg.triangle_cluster[t]].push_back(t);
  return out;
}

Segmentation one_cluster(const VoxelShape& shape) {
  Segmentation seg;
  seg.triangle_cluster.assign(shape.surface.triangles.size(), 0);
  seg.cluster_count = 1;
  seg.counts.clusters = 1;
  return seg;
}

/// A U in the x-y plane, one unit thick: base x in [0,5], y in [0,1]; arms x in [0,1] and
/// [4,5], y in [1,6]. No point sees both arms' inner faces (x = 1 facing +x, x = 4 facing -x).
VoxelShape u_shape() {
  return make_voxel_shape(5, 6, 1, 2,
                          [](double x, double y, double) { return y < 1.0 || x < 1.0 || x > 4.0; });
}

}  // namespace

TEST_CASE("The minimum cut equals the cheapest cut found by enumeration", "[refine]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> capacity(0.0, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const std::uint32_t n = 2 + static_cast<std::uint32_t>(rng() % 9);  // 2..10 vertices
    std::vector<Arc> arcs;
    tetseg::preprocess::detail::MinCut graph(n);
    const std::uint32_t edges = static_cast<std::uint32_t>(rng() % (3 * n));
    for (std::uint32_t e = 0; e < edges; ++e) {
      const std::uint32_t u = static_cast<std::uint32_t>(rng() % n);
      const std::uint32_t v = static_cast<std::uint32_t>(rng() % n);
      if (u == v) continue;
      const double forward = capacity(rng), backward = rng() % 2 ? capacity(rng) : 0.0;
      graph.add_edge(u, v, forward, backward);
      arcs.push_back({u, v, forward});
      arcs.push_back({v, u, backward});
    }
    const double flow = graph.run(0, n - 1, 1e-12);
    CAPTURE(trial, n, edges);
    REQUIRE(flow == Approx(brute_min_cut(n, arcs, 0, n - 1)).margin(1e-9));
    // The reported source side is a cut of exactly that capacity.
    const std::vector<std::uint8_t> side = graph.source_side(0, 1e-12);
    REQUIRE(side[0] == 1);
    REQUIRE(side[n - 1] == 0);
    double cut = 0.0;
    for (const Arc& a : arcs)
      if (side[a.u] && !side[a.v]) cut += a.capacity;
    REQUIRE(cut == Approx(flow).margin(1e-9));
  }
}

TEST_CASE("A U-shaped cluster is split into parts its own nodes see whole", "[refine]") {
  const VoxelShape u = u_shape();
  const Segmentation before = one_cluster(u);
  const std::vector<double> density(u.surface.triangles.size(), 0.5);
  const double visibility_before = brute_visibility(u, members(before)[0]);
  RefinementOptions options;
  REQUIRE(visibility_before < options.min_visibility);  // the premise: no node sees it whole
  options.min_cluster_triangles = 8;
  RefinementCounts counts;
  const Segmentation after = refine_clusters(u.nodes, u.surface, density, before, options, &counts);
  check_segmentation_invariants(u.surface.triangles, after);
  CHECK(counts.clusters_before == 1);
  CHECK(counts.splits >= 1);
  CHECK(after.cluster_count == 1 + counts.splits - counts.merges);
  // Every part is seen at least as well as the threshold, by brute force over all nodes, and
  // the detector search finds it.
  const auto parts = members(after);
  const std::vector<Detector> detectors =
      choose_detectors(u.nodes, u.surface, after.triangle_cluster, after.cluster_count,
                       DetectorStrategy::kVisibility);
  for (std::uint32_t c = 0; c < after.cluster_count; ++c) {
    CAPTURE(c, parts[c].size());
    CHECK(brute_visibility(u, parts[c]) >= options.min_visibility);
    CHECK(detectors[c].rest_positive_fraction >= options.min_visibility);
  }
  // Deterministic.
  const Segmentation again = refine_clusters(u.nodes, u.surface, density, before, options);
  CHECK(again.triangle_cluster == after.triangle_cluster);
  CHECK(again.boundary_loops == after.boundary_loops);
}

TEST_CASE("Refinement respects the cluster bound and the minimum size", "[refine]") {
  const VoxelShape u = u_shape();
  const std::vector<double> density(u.surface.triangles.size(), 0.5);
  RefinementOptions options;
  options.min_cluster_triangles = 8;
  options.max_clusters = 2;
  options.merge = false;
  const Segmentation two = refine_clusters(u.nodes, u.surface, density, one_cluster(u), options);
  check_segmentation_invariants(u.surface.triangles, two);
  CHECK(two.cluster_count == 2);

  options.max_clusters = 32;
  options.min_cluster_triangles =
      static_cast<std::uint32_t>(u.surface.triangles.size());  // no piece can be this large
  RefinementCounts counts;
  const Segmentation none =
      refine_clusters(u.nodes, u.surface, density, one_cluster(u), options, &counts);
  CHECK(none.cluster_count == 1);
  CHECK(counts.splits == 0);
}

TEST_CASE("Two halves of a box merge into one cluster, and star-shaped clusters stay", "[refine]") {
  const VoxelShape box = make_voxel_shape(4, 2, 2, 1, [](double, double, double) { return true; });
  Segmentation halves;
  halves.cluster_count = 2;
  for (std::uint32_t t = 0; t < box.surface.triangles.size(); ++t)
    halves.triangle_cluster.push_back(tetseg::test::triangle_centroid(box, t)[0] < 2.0 ? 0 : 1);
  halves.counts.clusters = 2;
  const std::vector<double> density(box.surface.triangles.size(), 0.5);

  RefinementOptions options;
  RefinementCounts counts;
  const Segmentation merged =
      refine_clusters(box.nodes, box.surface, density, halves, options, &counts);
  CHECK(merged.cluster_count == 1);
  CHECK(counts.merges == 1);
  CHECK(counts.splits == 0);
  CHECK(merged.boundary_loops.empty());

  options.merge = false;
  const Segmentation kept = refine_clusters(box.nodes, box.surface, density, halves, options);
  check_segmentation_invariants(box.surface.triangles, kept);
  CHECK(kept.triangle_cluster == halves.triangle_cluster);
  CHECK(kept.boundary_loops.size() == 1);
}

TEST_CASE("Refinement rejects inputs that do not match the surface", "[refine]") {
  const VoxelShape box = make_voxel_shape(2, 2, 2, 1, [](double, double, double) { return true; });
  const std::vector<double> density(box.surface.triangles.size(), 0.5);
  Segmentation bad = one_cluster(box);
  bad.triangle_cluster[0] = 3;
  CHECK_THROWS_AS(refine_clusters(box.nodes, box.surface, density, bad, {}), std::invalid_argument);
  CHECK_THROWS_AS(refine_clusters(box.nodes, box.surface, {0.5}, one_cluster(box), {}),
                  std::invalid_argument);
  Surface no_interior = box.surface;
  no_interior.interior_nodes.clear();
  CHECK_THROWS_AS(refine_clusters(box.nodes, no_interior, density, one_cluster(box), {}),
                  InputError);
}
