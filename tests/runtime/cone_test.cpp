// Normal-cone mode (ColliderMode::kCone): on deforming sequences it reports exactly the
// contacts brute force finds (the mode only skips patches proven embedded for the whole step),
// while actually culling node self-tests.

#include <algorithm>
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "support/compare.hpp"
#include "tetseg/runtime/body_shape.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

namespace tetseg::test {
namespace {

struct ConeReport {
  int steps = 0, contact_steps = 0;
  std::uint64_t cone_culled = 0, cone_pairs = 0, bvh_pairs = 0;
};

/// Steps until (and including) the first contact: cone equals brute (any, earliest, every
/// contact); later steps may start self-intersecting and are not compared.
ConeReport compare_cone(const Scene& scene, const std::vector<std::vector<double>>& frames) {
  Collider cone = collider_for(scene, ColliderMode::kCone);
  Collider bvh = collider_for(scene, ColliderMode::kBvh);
  Collider brute = collider_for(scene, ColliderMode::kBrute);
  REQUIRE(cone.status() == ColliderStatus::kOk);
  ConeReport rep;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    CAPTURE(f);
    const StepAnswer b = answer(brute, frames[f].data(), frames[f + 1].data());
    const StepAnswer c = answer(cone, frames[f].data(), frames[f + 1].data());
    (void)answer(bvh, frames[f].data(), frames[f + 1].data());
    ++rep.steps;
    rep.cone_culled += cone.stats().node_pairs_orientation_culled;
    rep.cone_pairs += cone.stats().triangle_pairs;
    rep.bvh_pairs += bvh.stats().triangle_pairs;
    REQUIRE(c.any == b.any);
    REQUIRE(c.contacts.size() == b.contacts.size());
    for (std::size_t i = 0; i < b.contacts.size(); ++i) {
      CAPTURE(describe(b.contacts[i]));
      REQUIRE(same_feature(c.contacts[i], b.contacts[i]));
      CHECK(c.contacts[i].toi == b.contacts[i].toi);
    }
    if (b.any) {
      ++rep.contact_steps;
      REQUIRE(c.earliest.found);
      CHECK(c.earliest.contact.toi == b.earliest.contact.toi);
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
    CHECK(r.steps > 0);
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
  for (const auto& end : ends) {
    std::vector<StepAnswer> answers;
    for (ColliderMode mode : {ColliderMode::kBrute, ColliderMode::kBvh, ColliderMode::kCone}) {
      ColliderOptions options;
      options.mode = mode;
      Collider collider(shape, options);
      REQUIRE(collider.status() == ColliderStatus::kOk);
      answers.push_back(answer(collider, start.data(), end.data()));
      if (mode != ColliderMode::kBrute) CHECK(collider.stats().triangle_pairs == 0);
    }
    const StepAnswer& b = answers[0];
    REQUIRE(b.any);
    for (std::size_t m = 1; m < answers.size(); ++m) {
      const StepAnswer& a = answers[m];
      CAPTURE(m);
      REQUIRE(a.contacts.size() == b.contacts.size());
      for (std::size_t i = 0; i < b.contacts.size(); ++i) {
        CAPTURE(describe(b.contacts[i]));
        CHECK(same_feature(a.contacts[i], b.contacts[i]));
        CHECK(a.contacts[i].toi == b.contacts[i].toi);
      }
      CHECK(a.earliest.contact.toi == b.earliest.contact.toi);
    }
  }
}

}  // namespace tetseg::test
