// Normal-cone mode (ColliderMode::kCone): on deforming sequences it reports exactly the
// contacts the brute-force scene oracle finds (the mode only skips patches proven embedded for the
// whole step), while actually culling node self-tests.

#include <algorithm>
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "runtime/support/compare.hpp"
#include "tetseg/runtime/body_shape.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

namespace tetseg::test {
namespace {

struct ConeReport {
  int steps = 0, contact_steps = 0;
  std::uint64_t cone_culled = 0, cone_pairs = 0, bvh_pairs = 0;
};

/// Steps until (and including) the first contact: cone finds exactly the oracle's contacts
/// (compare.hpp: any, earliest, every contact at the same toi, the exact contacts); later steps
/// may start self-intersecting and are not compared.
ConeReport compare_cone(const Scene& scene, const std::vector<std::vector<double>>& frames) {
  Collider cone = collider_for(scene, ColliderMode::kCone);
  Collider bvh = collider_for(scene, ColliderMode::kBvh);
  REQUIRE(cone.status() == ColliderStatus::kOk);
  ConeReport rep;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    CAPTURE(f);
    const double* x0 = frames[f].data();
    const double* x1 = frames[f + 1].data();
    const StepTruth truth = step_truth(scene, x0, x1);
    const StepAnswer c = answer(cone, x0, x1);
    (void)answer(bvh, x0, x1);
    ++rep.steps;
    rep.cone_culled += cone.stats().node_pairs_orientation_culled;
    rep.cone_pairs += cone.stats().triangle_pairs;
    rep.bvh_pairs += bvh.stats().triangle_pairs;
    require_matches_oracle(c, truth, Expect::kAllContacts);
    if (!truth.oracle.empty()) {
      ++rep.contact_steps;
      break;
    }
  }
  return rep;
}

}  // namespace

TEST_CASE("Normal-cone mode finds every contact of a bent dumbbell", "[collider][cone]") {
  const Scene scene = make_axial_scene(dumbbell(16, 26), {-0.6, 0.6}, {-1.6, 0.0, 1.6});
  const auto frames = make_frames(
      scene, 16, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
  const ConeReport r = compare_cone(scene, frames);
  CHECK(r.contact_steps == 1);  // the bells meet within the sequence
  CHECK(r.cone_culled > 0);     // patches were proven free and skipped
  CHECK(r.cone_pairs < r.bvh_pairs);
}

TEST_CASE("Normal-cone mode finds every contact of a twisted pawn folding onto itself",
          "[collider][cone]") {
  const Scene scene = make_axial_scene(pawn(16, 30), {1.0, 2.6}, {0.4, 1.6, 3.3});
  const auto frames = make_frames(scene, 16, twist_bend);
  const ConeReport r = compare_cone(scene, frames);
  CHECK(r.contact_steps == 1);
  CHECK(r.cone_culled > 0);
}

TEST_CASE("Normal-cone mode agrees with brute force under random smooth waves",
          "[collider][cone]") {
  const Scene scene = make_axial_scene(sphere(1.0, 20, 11), {0.0}, {-0.45, 0.45});
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    CAPTURE(seed);
    std::mt19937 rng(seed);
    auto u = [&] { return (rng() / 4294967296.0) * 2 - 1; };
    std::vector<std::array<double, 7>> waves;
    for (int i = 0; i < 4; ++i)
      waves.push_back({3 * u(), 3 * u(), 3 * u(), 3 * u(), u(), u(), u()});
    const auto frames = make_frames(scene, 12, [&](const P3& p, double t) {
      P3 q = p;
      for (const auto& a : waves) {
        const double s = std::sin(a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + a[3]);
        for (int k = 0; k < 3; ++k) q[k] += t * 0.6 * s * a[4 + k];
      }
      return q;
    });
    const ConeReport r = compare_cone(scene, frames);
    CHECK(r.contact_steps == 1);  // the waves do reach a contact
  }
}

TEST_CASE("Normal-cone mode has a stable name", "[collider][cone]") {
  ColliderMode m = ColliderMode::kRvbc;
  CHECK(parse_collider_mode("cone", m));
  CHECK(m == ColliderMode::kCone);
  CHECK(std::string(to_string(ColliderMode::kCone)) == "cone");
}

TEST_CASE("Normal-cone mode lists every contact of two poles meeting head on",
          "[collider][cone][closure]") {
  // The degenerate meeting of docs/runtime.md (many feature pairs touch at one point at once).
  const Surface s = sphere(1.0, 20, 11);
  const Scene scene =
      make_scene(s, std::vector<std::uint32_t>(s.tris.size(), 0), {{0.3, 0.1, 0.05}});
  const auto frames = make_frames(scene, 16, press_poles_head_on);
  const ConeReport r = compare_cone(scene, frames);
  CHECK(r.contact_steps == 1);
}

TEST_CASE("Whole-surface modes find contacts of feature pairs held only by adjacent triangles",
          "[collider][cone][orphan]") {
  // A tetrahedron's surface: every two of its triangles share a node, so bvh and cone examine
  // no triangle pair and every feature pair (a vertex against the opposite face, two opposite
  // edges) is an orphan, tested directly. Motions: the apex pushed through the base, and the
  // tetrahedron flattened until two opposite edges cross.
  const std::uint32_t tris[] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
  const auto shape = BodyShape::from_triangles(tris, 4, 4);
  REQUIRE(shape);
  const std::vector<double> start = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 1};
  const std::vector<std::vector<double>> ends = {
      {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.25, 0.3, -1},        // apex through the base
      {0, 0, 0, 1, 0, 0, 0.1, 1, 0.2, 0.9, 0.8, -0.6}};  // edge 2-3 crosses edge 0-1
  std::vector<format::Triangle> triangles;
  for (int t = 0; t < 4; ++t) triangles.push_back({tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]});
  for (const auto& end : ends) {
    const OracleBody body{triangles.data(), triangles.size(), start.data(), end.data(), true};
    const StepTruth truth = step_truth(body);
    REQUIRE_FALSE(truth.required.empty());
    for (ColliderMode mode : {ColliderMode::kBrute, ColliderMode::kBvh, ColliderMode::kCone}) {
      CAPTURE(to_string(mode));
      ColliderOptions options;
      options.mode = mode;
      Collider collider(shape, options);
      REQUIRE(collider.status() == ColliderStatus::kOk);
      require_matches_oracle(answer(collider, start.data(), end.data()), truth,
                             Expect::kAllContacts);
      if (mode != ColliderMode::kBrute) CHECK(collider.stats().triangle_pairs == 0);
    }
  }
}

}  // namespace tetseg::test
