// Semantic validation: each documented rule is broken once on an otherwise valid asset, and
// the asset must be rejected both by validate() and by read_asset() on its written bytes.
#include <catch2/catch.hpp>

#include <limits>

#include "format/support/broken_rule.hpp"
#include "format/support/test_assets.hpp"

using namespace tetseg::format;
using namespace tetseg::test;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// A point-form detector (format 1.1) of the octahedron's upper tet (6, 0, 2, 4) by default.
DetectorPoint point(std::array<std::uint32_t, 4> nodes = {6, 0, 2, 4},
                    std::array<double, 4> weights = {0.625, 0.125, 0.125, 0.125}) {
  DetectorPoint d;
  d.nodes = nodes;
  d.weights = weights;
  d.tet = 0;
  return d;
}

// Octahedron ids (test_assets.hpp): surface nodes 0..5, detectors 6 and 7; triangles 0..3 in
// cluster 0, 4..7 in cluster 1; one loop {0, 2, 1, 3}. BVH nodes {first, second, count}:
// cluster 0: 0 {1,4,0}, 1 {2,3,0}, 2 {0,0,1}, 3 {1,0,1}, 4 {5,6,0}, 5 {2,0,1}, 6 {3,0,1};
// cluster 1: 7 {1,2,0}, 8 {0,0,2}, 9 {2,0,2} (child indices are local to each cluster).
const std::vector<BrokenRule>& rules() {
  static const std::vector<BrokenRule> table = {
      {"a triangle node id equals node_count", ">= node_count",
       [](Asset& a) { a.triangles[3][1] = a.node_count; }},
      {"a triangle node id is huge", ">= node_count",
       [](Asset& a) { a.triangles[0][0] = 0xFFFFFFFFu; }},
      {"a triangle repeats a node id", "repeats a node id",
       [](Asset& a) { a.triangles[5][2] = a.triangles[5][0]; }},
      {"node_count is over the limit", "the limit is",
       [](Asset& a) {
         a.rest_positions.clear();
         a.node_count = kMaxNodes + 1;
       }},
      {"rest_positions is one short of node_count", "node_count is",
       [](Asset& a) { a.rest_positions.pop_back(); }},
      {"rest_positions is one longer than node_count", "node_count is",
       [](Asset& a) {
         a.rest_positions.push_back({0, 0, 0});
       }},
      {"a rest position is NaN", "not finite",
       [](Asset& a) { a.rest_positions[2][1] = std::nan(""); }},
      {"a rest position is infinite", "not finite",
       [](Asset& a) { a.rest_positions[7][2] = -kInf; }},
      {"the asset has no triangles", "no surface triangles", [](Asset& a) { a = Asset{}; }},
      {"triangle_cluster is one short", "triangle_cluster has",
       [](Asset& a) { a.triangle_cluster.pop_back(); }},
      {"triangle_cluster names a cluster that does not exist", "triangle_cluster says",
       [](Asset& a) { a.triangle_cluster[1] = 2; }},
      {"triangle_cluster disagrees with the cluster lists", "triangle_cluster says",
       [](Asset& a) { a.triangle_cluster[0] = 1; }},
      {"a triangle is listed twice", "more than one cluster",
       [](Asset& a) { a.cluster_triangles[1] = a.cluster_triangles[0]; }},
      {"a listed triangle id is out of range", "out of range",
       [](Asset& a) { a.cluster_triangles[5] = 8; }},
      {"cluster_triangles has an extra entry", "cluster_triangles has",
       [](Asset& a) { a.cluster_triangles.push_back(0); }},
      {"there are triangles but no clusters", "no clusters",
       [](Asset& a) {
         a.clusters.clear();
         a.bvh_nodes.clear();
       }},
      {"a cluster has no triangles", "has no triangles",
       [](Asset& a) { a.clusters[1].triangle_count = 0; }},
      {"cluster triangle ranges leave a gap", "clusters are contiguous",
       [](Asset& a) {
         a.clusters[0].triangle_count = 3;
         a.clusters[1].triangle_offset = 4;
       }},
      {"cluster triangle ranges overlap", "clusters are contiguous",
       [](Asset& a) { a.clusters[1].triangle_offset = 3; }},
      {"the clusters do not cover all triangles", "clusters cover",
       [](Asset& a) { a.clusters[1].triangle_count = 3; }},
      {"a cluster range runs past the list", "triangle range exceeds",
       [](Asset& a) { a.clusters[1].triangle_count = 5; }},
      {"a huge triangle_count wraps", "triangle range exceeds",
       [](Asset& a) { a.clusters[0].triangle_count = 0xFFFFFFFFu; }},
      {"a detector node equals node_count", ">= node_count",
       [](Asset& a) { a.clusters[0].detector = DetectorPoint::at_node(8); }},
      {"a detector node is on the surface", "is a surface node",
       [](Asset& a) { a.clusters[1].detector = DetectorPoint::at_node(5); }},
      {"a point-form detector node equals node_count", ">= node_count",
       [](Asset& a) {
         a.clusters[0].detector = point({6, 0, 8, 4});
       }},
      {"a point-form detector node id is huge", ">= node_count",
       [](Asset& a) {
         a.clusters[1].detector = point({7, 0xFFFFFFFFu, 2, 4});
       }},
      {"a point-form detector repeats a node", "repeats node",
       [](Asset& a) {
         a.clusters[0].detector = point({6, 0, 0, 4});
       }},
      {"node-form weights with unequal ids repeat a node", "repeats node",
       [](Asset& a) {
         a.clusters[0].detector = point({6, 6, 6, 7}, {1, 0, 0, 0});
       }},
      {"equal ids without node-form weights repeat a node", "repeats node",
       [](Asset& a) {
         a.clusters[0].detector = point({6, 6, 6, 6}, {0.5, 0.5, 0, 0});
       }},
      {"a detector weight is negative", "not a finite non-negative",
       [](Asset& a) {
         a.clusters[0].detector = point({6, 0, 2, 4}, {1.25, -0.25, 0, 0});
       }},
      {"a detector weight is NaN", "not a finite non-negative",
       [](Asset& a) {
         a.clusters[1].detector = point({6, 0, 2, 4}, {std::nan(""), 1, 0, 0});
       }},
      {"a detector weight is infinite", "not a finite non-negative",
       [](Asset& a) {
         a.clusters[1].detector = point({6, 0, 2, 4}, {kInf, 0, 0, 0});
       }},
      {"detector weights sum above 1 + 1e-9", "sum to",
       [](Asset& a) {
         a.clusters[0].detector = point({6, 0, 2, 4}, {0.5, 0.5, 4e-9, 0});
       }},
      {"detector weights sum below 1 - 1e-9", "sum to",
       [](Asset& a) {
         a.clusters[0].detector = point({6, 0, 2, 4}, {0.25, 0.25, 0.25, 0.2499});
       }},
      {"detector weights are all zero", "sum to",
       [](Asset& a) {
         a.clusters[0].detector = point({6, 0, 2, 4}, {0, 0, 0, 0});
       }},
      {"a cluster flag is unknown", "unknown bits", [](Asset& a) { a.clusters[1].flags = 2; }},
      {"a cluster flag is unknown beside overlap-only", "unknown bits",
       [](Asset& a) { a.clusters[0].flags = kClusterOverlapOnly | 0x80000000u; }},
      {"rest_positive_fraction is NaN", "in [0,1]",
       [](Asset& a) { a.clusters[0].rest_positive_fraction = kNaN; }},
      {"rest_positive_fraction is negative", "in [0,1]",
       [](Asset& a) { a.clusters[0].rest_positive_fraction = -0.25f; }},
      {"rest_positive_fraction is above one", "in [0,1]",
       [](Asset& a) { a.clusters[1].rest_positive_fraction = 1.5f; }},
      {"rest_positive_fraction is infinite", "in [0,1]",
       [](Asset& a) {
         a.clusters[1].rest_positive_fraction = std::numeric_limits<float>::infinity();
       }},
      {"a cluster has no BVH nodes", "no BVH nodes",
       [](Asset& a) {
         a.clusters[1].bvh_count = 0;
         a.bvh_nodes.resize(7);
       }},
      {"BVH ranges leave a gap", "BVHs are contiguous",
       [](Asset& a) { a.clusters[1].bvh_offset = 8; }},
      {"BVH ranges do not use every node", "BVH nodes",
       [](Asset& a) {
         a.bvh_nodes.push_back({0, 0, 1});
       }},
      {"a BVH range runs past bvh_nodes", "BVH range exceeds",
       [](Asset& a) { a.clusters[1].bvh_count = 4; }},
      {"a child index is not larger than its parent", "child 1 is not in",
       [](Asset& a) { a.bvh_nodes[1].first = 1; }},
      {"a child points at the root", "child 0 is not in",
       [](Asset& a) { a.bvh_nodes[4].second = 0; }},
      {"a child index is past the cluster's BVH", "child 3 is not in",
       [](Asset& a) { a.bvh_nodes[7].second = 3; }},
      {"a node has two parents", "has two parents",
       [](Asset& a) {
         // Node 1's right child becomes 5, which node 4 also owns.
         a.bvh_nodes[1] = {2, 5, 0};
       }},
      {"both children are the same node", "has two parents",
       [](Asset& a) { a.bvh_nodes[0].second = a.bvh_nodes[0].first; }},
      {"a leaf has a non-zero second field", "non-zero second",
       [](Asset& a) { a.bvh_nodes[3].second = 1; }},
      {"a leaf runs past the cluster's triangles", "leaf range exceeds",
       [](Asset& a) { a.bvh_nodes[9].count = 3; }},
      {"two leaves cover the same triangle", "in two leaves",
       [](Asset& a) { a.bvh_nodes[3].first = 0; }},
      {"a leaf's first triangle is huge", "leaf range exceeds",
       [](Asset& a) { a.bvh_nodes[8].first = 0xFFFFFFFFu; }},
      {"a leaf has no parent", "has no parent",
       [](Asset& a) {
         // Cluster 1 becomes two leaves that cover its triangles, but the root is one of them.
         a.bvh_nodes.resize(9);
         a.bvh_nodes[7] = {0, 0, 2};
         a.bvh_nodes[8] = {2, 0, 2};
         a.clusters[1].bvh_count = 2;
       }},
      {"a BVH is a single leaf that misses triangles", "in no leaf",
       [](Asset& a) {
         a.bvh_nodes.resize(8);
         a.bvh_nodes[7] = {0, 0, 3};
         a.clusters[1].bvh_count = 1;
       }},
      {"a boundary loop has two nodes", "fewer than 3",
       [](Asset& a) {
         a.boundary_nodes = {0, 2};
         a.boundaries[0].node_count = 2;
       }},
      {"a boundary loop has no nodes", "fewer than 3",
       [](Asset& a) {
         a.boundary_nodes.clear();
         a.boundaries[0].node_count = 0;
       }},
      {"consecutive loop nodes are not a surface edge", "nodes 0 and 1 are not a surface edge",
       [](Asset& a) {
         a.boundary_nodes = {0, 1, 2, 3};
       }},
      {"the closing loop edge is not a surface edge", "nodes 1 and 0 are not a surface edge",
       [](Asset& a) {
         a.boundary_nodes = {0, 2, 1};  // 0-2 and 2-1 are edges, 1-0 is not
         a.boundaries[0].node_count = 3;
       }},
      {"a loop node is out of range", ">= node_count", [](Asset& a) { a.boundary_nodes[0] = 8; }},
      {"a loop repeats a node in place of an edge", "not a surface edge",
       [](Asset& a) { a.boundary_nodes[1] = 0; }},
      {"loop ranges leave a gap", "loops are contiguous",
       [](Asset& a) {
         a.boundary_nodes.insert(a.boundary_nodes.begin(), 4);
         a.boundaries[0].node_offset = 1;
       }},
      {"loops do not use every boundary node", "boundaries use",
       [](Asset& a) { a.boundary_nodes.push_back(4); }},
      {"a loop runs past boundary_nodes", "exceeds boundary_nodes",
       [](Asset& a) { a.boundaries[0].node_count = 5; }},
      {"a loop offset is huge", "loops are contiguous",
       [](Asset& a) { a.boundaries[0].node_offset = 0xFFFFFFF0u; }},
      {"provenance options are not sorted", "not sorted",
       [](Asset& a) { std::swap(a.provenance.options[0], a.provenance.options[1]); }},
      {"provenance options repeat a key", "not sorted",
       [](Asset& a) { a.provenance.options[1].first = a.provenance.options[0].first; }},
      {"the tool version string is over the limit", "the limit is",
       [](Asset& a) { a.provenance.tool_version.assign(kMaxStringBytes + 1, 'v'); }},
      {"an option key is over the limit", "the limit is",
       [](Asset& a) { a.provenance.options[2].first.assign(kMaxStringBytes + 1, 'z'); }},
  };
  return table;
}

}  // namespace

TEST_CASE("Each validation rule rejects an asset that breaks it", "[format][validate]") {
  const Asset valid = make_octahedron_asset();
  REQUIRE(validate(valid) == Status::kOk);
  {
    // The table's comment on BVH layout is what make_octahedron_asset builds.
    const std::vector<std::array<std::uint32_t, 3>> layout = {
        {1, 4, 0}, {2, 3, 0}, {0, 0, 1}, {1, 0, 1}, {5, 6, 0},
        {2, 0, 1}, {3, 0, 1}, {1, 2, 0}, {0, 0, 2}, {2, 0, 2}};
    REQUIRE(valid.bvh_nodes.size() == layout.size());
    for (std::size_t i = 0; i < layout.size(); ++i) {
      CAPTURE(i);
      CHECK(valid.bvh_nodes[i].first == layout[i][0]);
      CHECK(valid.bvh_nodes[i].second == layout[i][1]);
      CHECK(valid.bvh_nodes[i].count == layout[i][2]);
    }
  }
  const std::size_t index = GENERATE(range(std::size_t(0), rules().size()));
  const BrokenRule& rule = rules()[index];
  CAPTURE(rule.name);
  check_refused(rule);
}

TEST_CASE("Validation accepts the legitimate variations", "[format][validate]") {
  Asset a = make_octahedron_asset();
  SECTION("Rest positions may be stripped.") {
    a.rest_positions.clear();
  }
  SECTION("An asset may have no boundary loops.") {
    a.boundaries.clear();
    a.boundary_nodes.clear();
  }
  SECTION("Clusters may share a detector node.") {
    a.clusters[1].detector = DetectorPoint::at_node(6);
  }
  SECTION("Point-form detectors: a tet's point, its nodes on the surface or not.") {
    a.clusters[0].detector = point();
    a.clusters[1].detector = point({7, 6, 1, 3}, {0.25, 0.25, 0.25, 0.25});
  }
  SECTION("A point-form detector may sit at one of its nodes, even a surface node.") {
    a.clusters[0].detector = point({4, 0, 2, 6}, {1, 0, 0, 0});
  }
  SECTION("Weights may miss 1 by up to the documented bound, and the tet id is free.") {
    a.clusters[0].detector = point({6, 0, 2, 4}, {0.5, 0.5, 5e-10, 0});
    a.clusters[1].detector = point({7, 6, 1, 3}, {0.25, 0.25, 0.25, 0.25 - 5e-10});
    a.clusters[1].detector.tet = kNoTet;
  }
  SECTION("A cluster may be flagged overlap-only, and so may all.") {
    a.clusters[0].flags = kClusterOverlapOnly;
    a.clusters[1].flags = kClusterOverlapOnly;
  }
  SECTION("Interior nodes need not be detectors, and fractions 0 and 1 are in range.") {
    a.rest_positions.push_back({0.1, 0.1, 0.1});
    a.node_count = 9;
    a.clusters[0].rest_positive_fraction = 0.0f;
    a.clusters[1].rest_positive_fraction = 1.0f;
  }
  SECTION("A loop may run around a single triangle.") {
    a.boundary_nodes = {0, 2, 4};
    a.boundaries[0].node_count = 3;
  }
  SECTION("A whole cluster may be one leaf.") {
    a.bvh_nodes.resize(8);
    a.bvh_nodes[7] = {0, 0, 4};
    a.clusters[1].bvh_count = 1;
  }
  SECTION("Provenance may be empty.") {
    a.provenance = {};
  }
  std::string why;
  CHECK(validate(a, &why) == Status::kOk);
  INFO(why);
  const auto bytes = write_asset(a);
  Asset out;
  CHECK(read_asset(bytes.data(), bytes.size(), out) == Status::kOk);
  CHECK(assets_equal(a, out));
}

TEST_CASE(
    "A larger asset with many clusters validates and a broken BVH in its last "
    "cluster is found",
    "[format][validate]") {
  Asset a = make_cube_asset(6);
  REQUIRE(a.clusters.size() == 6);
  REQUIRE(validate(a) == Status::kOk);
  const Cluster& last = a.clusters.back();
  a.bvh_nodes[last.bvh_offset + last.bvh_count - 1].count += 1;
  CHECK(validate(a) == Status::kInvalidContent);
}
