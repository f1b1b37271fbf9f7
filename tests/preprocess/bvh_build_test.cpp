#include <algorithm>
#include <catch2/catch.hpp>
#include <random>

#include "tetseg/preprocess/segmentation.hpp"

using namespace tetseg::preprocess;

namespace {

struct Soup {
  std::vector<Vec3> nodes;
  std::vector<Tri> triangles;
};

Soup random_soup(std::uint32_t triangle_count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  Soup soup;
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    Tri tri;
    for (int k = 0; k < 3; ++k) {
      tri[k] = static_cast<std::uint32_t>(soup.nodes.size());
      soup.nodes.push_back({coordinate(rng), coordinate(rng), coordinate(rng)});
    }
    soup.triangles.push_back(tri);
  }
  return soup;
}

// Walks the tree from the root: every node reached once, children after parents, leaves cover
// the local triangle list exactly once. Returns the leaf depth maximum.
int check_tree(const ClusterBvh& bvh) {
  std::vector<int> reached(bvh.nodes.size(), 0);
  std::vector<int> covered(bvh.triangles.size(), 0);
  std::vector<std::pair<std::uint32_t, int>> stack{{0, 0}};
  int max_depth = 0;
  while (!stack.empty()) {
    const auto [index, depth] = stack.back();
    stack.pop_back();
    REQUIRE(index < bvh.nodes.size());
    ++reached[index];
    const auto& node = bvh.nodes[index];
    if (node.count > 0) {
      max_depth = std::max(max_depth, depth);
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) ++covered.at(i);
    } else {
      REQUIRE(node.first > index);
      REQUIRE(node.second > index);
      stack.push_back({node.first, depth + 1});
      stack.push_back({node.second, depth + 1});
    }
  }
  for (int r : reached) REQUIRE(r == 1);
  for (int c : covered) REQUIRE(c == 1);
  return max_depth;
}

}  // namespace

TEST_CASE("A cluster BVH is a full binary tree over exactly the cluster's triangles", "[bvh]") {
  const std::uint32_t count = GENERATE(1u, 2u, 3u, 17u, 1000u);
  CAPTURE(count);
  const Soup soup = random_soup(count + 50, 7);
  std::vector<std::uint32_t> ids;
  for (std::uint32_t t = 0; t < count; ++t) ids.push_back(t * 3 % (count + 50));
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());

  const ClusterBvh bvh = build_cluster_bvh(soup.nodes, soup.triangles, ids);
  REQUIRE(bvh.triangles.size() == ids.size());
  REQUIRE(bvh.nodes.size() == 2 * ids.size() - 1);
  std::vector<std::uint32_t> sorted = bvh.triangles;
  std::sort(sorted.begin(), sorted.end());
  REQUIRE(sorted == ids);
  const int depth = check_tree(bvh);
  // A median split is balanced: depth is ceil(log2(n)).
  int expected = 0;
  while ((std::size_t{1} << expected) < ids.size()) ++expected;
  REQUIRE(depth == expected);
}

TEST_CASE("The BVH build does not depend on the order of the given triangle ids", "[bvh]") {
  const Soup soup = random_soup(300, 11);
  std::vector<std::uint32_t> ids(300);
  for (std::uint32_t t = 0; t < 300; ++t) ids[t] = t;
  const ClusterBvh a = build_cluster_bvh(soup.nodes, soup.triangles, ids);
  std::reverse(ids.begin(), ids.end());
  const ClusterBvh b = build_cluster_bvh(soup.nodes, soup.triangles, ids);
  REQUIRE(a.triangles == b.triangles);
  REQUIRE(a.nodes.size() == b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    REQUIRE(a.nodes[i].first == b.nodes[i].first);
    REQUIRE(a.nodes[i].second == b.nodes[i].second);
    REQUIRE(a.nodes[i].count == b.nodes[i].count);
  }
}

TEST_CASE("A BVH split separates triangles along the longest axis", "[bvh]") {
  // Triangles along x: the root's left subtree holds the lower half of x.
  std::vector<Vec3> nodes;
  std::vector<Tri> triangles;
  for (std::uint32_t t = 0; t < 8; ++t) {
    const double x = 10.0 * t;
    const auto base = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back({x, 0.0, 0.0});
    nodes.push_back({x + 1.0, 0.0, 0.0});
    nodes.push_back({x, 1.0, 0.0});
    triangles.push_back({base, base + 1, base + 2});
  }
  std::vector<std::uint32_t> ids{7, 3, 5, 1, 0, 2, 6, 4};
  const ClusterBvh bvh = build_cluster_bvh(nodes, triangles, ids);
  const auto& root = bvh.nodes[0];
  REQUIRE(root.count == 0);
  std::vector<std::uint32_t> left_leaves;
  std::vector<std::uint32_t> stack{root.first};
  while (!stack.empty()) {
    const auto& node = bvh.nodes[stack.back()];
    stack.pop_back();
    if (node.count) {
      left_leaves.push_back(bvh.triangles[node.first]);
    } else {
      stack.push_back(node.first);
      stack.push_back(node.second);
    }
  }
  std::sort(left_leaves.begin(), left_leaves.end());
  REQUIRE(left_leaves == std::vector<std::uint32_t>{0, 1, 2, 3});
}
