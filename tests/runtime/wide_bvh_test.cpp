// The 4-wide cluster BVHs (docs/runtime.md, "4-wide cluster BVHs") against brute force: rvbc's
// traversal must hand on exactly the non-culled triangle pairs, counted here over all triangle
// pairs from the positions and the collider's triangle classes, whether the trees are built
// from rest positions (surface-area splits) or collapsed from the asset's binary trees (leaves
// of 1, 2, 3 or 7 triangles, or chains of single-triangle leaves), on adversarial motions; and
// the contacts must agree with brute force (tests/runtime/support/compare.hpp).

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <vector>

#include "runtime/support/compare.hpp"
#include "runtime/support/motions.hpp"
#include "runtime/support/queries.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using namespace tetseg;
using namespace tetseg::test;

namespace {

// The scene's asset without rest positions (the same frames): the wide trees are then the
// asset's binary trees collapsed, not the surface-area trees built from rest positions.
Scene without_rest_positions(const Scene& scene) {
  format::Asset a = scene.asset.data();
  a.rest_positions.clear();
  Scene out = load_scene(a, scene.surface_nodes);
  out.rest = scene.rest;
  return out;
}

// The triangle pairs rvbc must examine in the step x0 -> x1, by brute force over all pairs:
// not both triangles still, swept boxes overlapping (min_separation 0), not in one cluster
// with the same proven class (the collider's classes for this step), and not of two clusters
// sharing a node.
std::uint64_t non_culled_pairs(const Scene& scene, const Collider& rvbc, const double* x0,
                               const double* x1) {
  const format::Asset& a = scene.asset.data();
  const std::size_t nt = a.triangles.size();
  std::vector<std::array<double, 6>> box(nt);
  std::vector<bool> moving(nt, false);
  for (std::size_t t = 0; t < nt; ++t) {
    box[t] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (std::uint32_t v : a.triangles[t]) {
      for (int k = 0; k < 3; ++k) {
        const double p = x0[3 * v + k], q = x1[3 * v + k];
        moving[t] = moving[t] || p != q;
        box[t][k] = std::min({box[t][k], p, q});
        box[t][3 + k] = std::max({box[t][3 + k], p, q});
      }
    }
  }
  std::uint64_t count = 0;
  for (std::size_t t1 = 0; t1 < nt; ++t1) {
    for (std::size_t t2 = t1 + 1; t2 < nt; ++t2) {
      if (!moving[t1] && !moving[t2]) continue;
      bool overlap = true;
      for (int k = 0; k < 3; ++k)
        overlap = overlap && box[t1][k] <= box[t2][3 + k] && box[t2][k] <= box[t1][3 + k];
      if (!overlap) continue;
      if (a.triangle_cluster[t1] != a.triangle_cluster[t2]) {
        // Across clusters a pair sharing a node is culled (its feature pairs: seam orphans).
        const auto& n1 = a.triangles[t1];
        const auto& n2 = a.triangles[t2];
        if (std::find_first_of(n1.begin(), n1.end(), n2.begin(), n2.end()) != n1.end()) continue;
      } else {
        const Orientation c = rvbc.triangle_class(t1);
        if (c != Orientation::kUncertain && c == rvbc.triangle_class(t2)) continue;
      }
      ++count;
    }
  }
  return count;
}

}  // namespace

TEST_CASE("The 4-wide cluster traversal examines exactly the non-culled triangle pairs",
          "[collider][rvbc][wide]") {
  const std::uint32_t leaf_size = GENERATE(0u, 1u, 2u, 3u, 7u);
  const unsigned seed = GENERATE(1u, 2u, 3u);
  const int shape = GENERATE(0, 1);
  const bool rest = GENERATE(true, false);
  CAPTURE(leaf_size, seed, shape, rest);
  const Surface s = shape == 0 ? sphere(1.0, 16, 9) : dumbbell(12, 18);
  const Scene with_rest =
      shape == 0 ? make_axial_scene(s, {-0.3, 0.4}, {-0.7, 0.0, 0.7}, leaf_size)
                 : make_axial_scene(s, {-0.8, 0.0, 0.8}, {-1.5, -0.4, 0.4, 1.5}, leaf_size);
  const Scene scene = rest ? with_rest : without_rest_positions(with_rest);
  // Large waves: the surface folds through itself, so boxes overlap everywhere and classes
  // are mixed; every step is counted, contacts or not.
  const Waves waves(seed, 1.2, 4.0);
  const auto frames = make_frames(scene, 10, waves);
  Collider rvbc = collider_for(scene, ColliderMode::kRvbc);
  REQUIRE(rvbc.status() == ColliderStatus::kOk);
  std::uint64_t examined = 0, culled = 0;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    CAPTURE(f);
    REQUIRE(rvbc.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    earliest_ok(rvbc);  // a full traversal
    const std::uint64_t expected =
        non_culled_pairs(scene, rvbc, frames[f].data(), frames[f + 1].data());
    REQUIRE(rvbc.stats().triangle_pairs == expected);
    examined += expected;
    culled += rvbc.stats().node_pairs_orientation_culled;
  }
  CHECK(examined > 0);
  CHECK(culled > 0);  // the sign bits did cull
}

TEST_CASE("rvbc over 4-wide trees (surface-area, or collapsed asset BVHs) agrees with brute force",
          "[collider][rvbc][wide]") {
  const std::uint32_t leaf_size = GENERATE(0u, 3u, 7u);
  const unsigned seed = GENERATE(4u, 5u);
  const bool rest = GENERATE(true, false);
  CAPTURE(leaf_size, seed, rest);
  const Surface s = dumbbell(14, 22);
  const Scene with_rest = make_axial_scene(s, {-1.0, 0.0, 1.0}, {-1.6, -0.5, 0.5, 1.6}, leaf_size);
  const Scene scene = rest ? with_rest : without_rest_positions(with_rest);
  const Waves waves(seed, 0.9, 4.0);
  const SequenceReport rep = compare_with_oracle(scene, make_frames(scene, 12, waves));
  CHECK(rep.contact_frames == 1);  // the waves do reach a contact
}
