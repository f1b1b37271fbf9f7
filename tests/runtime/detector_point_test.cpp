// Detector points inside tets (asset format 1.1) and overlap-only clusters in the runtime:
// the classification against a detector point never contradicts exact rational arithmetic
// (GMP), inverted and degenerate detector tets keep the collider's contacts equal to brute
// force, and flagged clusters are culled by overlap only.

#include <gmpxx.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "runtime/support/compare.hpp"
#include "runtime/support/motions.hpp"
#include "runtime/support/scenes.hpp"
#include "tetseg/format/asset.hpp"
#include "tetseg/runtime/classify.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/exact_poly.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using namespace tetseg;
using namespace tetseg::test;

namespace {

using tetseg::test::exact::negated;
using tetseg::test::exact::Poly;
using tetseg::test::exact::positive_on_unit_interval;

using Q3 = std::array<mpq_class, 3>;

Q3 rational(const double* p) {
  return {mpq_class(p[0]), mpq_class(p[1]), mpq_class(p[2])};
}

mpq_class det3(const Q3& u, const Q3& v, const Q3& w) {
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/// Exact cubic det[a(t)-o(t), b(t)-o(t), c(t)-o(t)] for points moving linearly from p0[i] to
/// p1[i] (i = o, a, b, c).
Poly orientation_cubic(const double* const p0[4], const double* const p1[4]) {
  Q3 u0[3], du[3];
  const Q3 o0 = rational(p0[0]), o1 = rational(p1[0]);
  for (int i = 0; i < 3; ++i) {
    const Q3 a0 = rational(p0[i + 1]), a1 = rational(p1[i + 1]);
    for (int k = 0; k < 3; ++k) {
      u0[i][k] = a0[k] - o0[k];
      du[i][k] = (a1[k] - o1[k]) - u0[i][k];
    }
  }
  return {det3(u0[0], u0[1], u0[2]),
          det3(du[0], u0[1], u0[2]) + det3(u0[0], du[1], u0[2]) + det3(u0[0], u0[1], du[2]),
          det3(du[0], du[1], u0[2]) + det3(du[0], u0[1], du[2]) + det3(u0[0], du[1], du[2]),
          det3(du[0], du[1], du[2])};
}

}  // namespace

TEST_CASE("Classification against a detector point never contradicts exact arithmetic",
          "[detector][classify][exact]") {
  // Seven nodes: the detector's tet (0..3) and a surface triangle (4..6), at the start and the
  // end of a step. The runtime's detector is the rounded barycentric point at each end, moving
  // linearly in between (docs/runtime.md, "Detector points"); the truth is the exact sign of
  // the cubic for exactly that trajectory.
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_real_distribution<double> unit(0, 1);
  int definite = 0, uncertain = 0, degenerate_definite = 0;
  const int kTrials = 6000;
  for (int trial = 0; trial < kTrials; ++trial) {
    const int kind = trial % 6;  // 0,1 random; 2 near-flat; 3 inverting; 4 collapsing; 5 near plane
    const double scale = std::pow(10.0, (trial % 7) - 3);
    const double offset = trial % 5 == 0 ? 1e5 * scale : 0.0;
    double x0[7][3], x1[7][3];
    for (int i = 0; i < 7; ++i)
      for (int k = 0; k < 3; ++k) {
        x0[i][k] = offset + scale * u(rng);
        x1[i][k] = x0[i][k] + scale * 0.5 * u(rng);
      }
    // The tet sits near the middle of the triangle's far side most of the time.
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k) {
        x0[i][k] = offset + scale * (0.2 * u(rng) - (k == 2 ? 2.0 : 0.0));
        x1[i][k] = x0[i][k] + scale * 0.05 * u(rng);
      }
    if (kind == 2) {  // node 3 within 1e-13 of the plane of nodes 0..2 at both ends
      for (int k = 0; k < 3; ++k) {
        const double w = unit(rng);
        x0[3][k] = w * x0[0][k] + (1 - w) * x0[1][k] + 1e-13 * scale * u(rng);
        x1[3][k] = w * x1[0][k] + (1 - w) * x1[1][k] + 1e-13 * scale * u(rng);
      }
    } else if (kind == 3) {  // node 3 passes through the opposite face: the tet inverts
      for (int k = 0; k < 3; ++k) {
        const double c = (x0[0][k] + x0[1][k] + x0[2][k]) / 3;
        x1[3][k] = c - (x0[3][k] - c);
      }
    } else if (kind == 4) {  // the whole tet collapses onto one point at the end
      for (int i = 1; i < 4; ++i)
        for (int k = 0; k < 3; ++k) x1[i][k] = x1[0][k];
    }
    format::DetectorPoint d;
    d.nodes = {0, 1, 2, 3};
    switch (trial % 4) {
      case 0: {
        double sum = 0;
        for (double& w : d.weights) sum += (w = unit(rng));
        for (double& w : d.weights) w /= sum;
        break;
      }
      case 1:
        d.weights = {0.25, 0.25, 0.25, 0.25};
        break;
      case 2:
        d.weights = {0.5, 0.5, 0.0, 0.0};  // on an edge
        break;
      default:
        d.weights = {0.0, 0.0, 0.0, 1.0};  // at a vertex, point form
    }
    const std::array<double, 3> o0 = format::detector_position(d, &x0[0][0]);
    const std::array<double, 3> o1 = format::detector_position(d, &x1[0][0]);
    if (kind == 5) {  // the triangle's plane passes within rounding of the detector at t = 0
      for (int k = 0; k < 3; ++k) x0[6][k] = o0[k] + (o0[k] - x0[4][k]) + 1e-15 * scale * u(rng);
    }
    const Orientation cls =
        classify_orientation(o0.data(), x0[4], x0[5], x0[6], o1.data(), x1[4], x1[5], x1[6]);
    if (cls == Orientation::kUncertain) {
      ++uncertain;
      continue;
    }
    ++definite;
    if (kind >= 2) ++degenerate_definite;
    const double* p0[4] = {o0.data(), x0[4], x0[5], x0[6]};
    const double* p1[4] = {o1.data(), x1[4], x1[5], x1[6]};
    const Poly f = orientation_cubic(p0, p1);
    CAPTURE(trial, kind);
    if (cls == Orientation::kPositive) REQUIRE(positive_on_unit_interval(f));
    if (cls == Orientation::kNegative) REQUIRE(positive_on_unit_interval(negated(f)));
  }
  CHECK(definite > kTrials / 2);      // the check is not vacuous
  CHECK(degenerate_definite > 1000);  // degenerate detector tets are classified too
  CHECK(uncertain > 50);              // and uncertain cases occur (near-plane triangles)
}

TEST_CASE("The exact oracle itself: Sturm positivity on known cubics", "[detector][exact]") {
  CHECK(positive_on_unit_interval({1}));
  CHECK_FALSE(positive_on_unit_interval({}));
  CHECK_FALSE(positive_on_unit_interval({0, 1}));                      // t: zero at 0
  CHECK_FALSE(positive_on_unit_interval({mpq_class(1, 100), -1, 1}));  // roots near 0.01, 0.99
  CHECK_FALSE(positive_on_unit_interval({mpq_class(1, 4), -1, 1}));    // (t - 1/2)^2: touches 0
  CHECK_FALSE(positive_on_unit_interval({mpq_class(1, 5), -1, 1}));    // two roots in (0, 1)
  CHECK(positive_on_unit_interval({mpq_class(26, 100), -1, 1}));       // min 0.01 at 1/2
  // (t - 1/3)(t - 2/3)(t - 2) changes sign twice in (0, 1).
  CHECK_FALSE(positive_on_unit_interval({mpq_class(-4, 9), mpq_class(22, 9), -3, 1}));
}

TEST_CASE("A node-form detector is the node itself, bit for bit", "[detector]") {
  const double x[2][3] = {{0.1, -0.3, 1e300}, {std::nextafter(1.0, 2.0), -0.0, 5e-324}};
  const auto p = format::detector_position(format::DetectorPoint::at_node(1), &x[0][0]);
  for (int k = 0; k < 3; ++k) CHECK(std::signbit(p[k]) == std::signbit(x[1][k]));
  CHECK(p[0] == x[1][0]);
  CHECK(p[2] == x[1][2]);
}

namespace {

/// Moves the detector tets' nodes (the last 4 per cluster, with_detector_tets) on their own:
/// node 3 of every tet passes through the opposite face between frame 0 and the last frame
/// (flat at the middle: degenerate, then inverted), and when `fling`, node 0 also moves by
/// `fling` along x, taking the detector point out of the body.
void invert_detector_tets(const Scene& scene, std::vector<std::vector<double>>& frames,
                          double fling) {
  const std::size_t clusters = scene.asset.data().clusters.size();
  const std::size_t first = scene.rest.size() / 3 - 4 * clusters;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const double t = frames.size() > 1 ? double(f) / double(frames.size() - 1) : 0.0;
    for (std::size_t c = 0; c < clusters; ++c) {
      const std::size_t n0 = first + 4 * c;
      double* p[4];
      for (int i = 0; i < 4; ++i) p[i] = frames[f].data() + 3 * (n0 + i);
      for (int k = 0; k < 3; ++k) {
        const double face = (p[0][k] + p[1][k] + p[2][k]) / 3;
        const double rest = scene.rest[3 * (n0 + 3) + k];
        const double rest_face =
            (scene.rest[3 * n0 + k] + scene.rest[3 * (n0 + 1) + k] + scene.rest[3 * (n0 + 2) + k]) /
            3;
        p[3][k] = face + (1 - 2 * t) * (rest - rest_face);
      }
      p[0][0] += fling * t;
    }
  }
}

}  // namespace

TEST_CASE("Detector points inside tets find the first contacts that brute force finds",
          "[detector][collider][rvbc]") {
  SECTION("A pressed sphere, 1 and 2 clusters, detectors inside small tets.") {
    for (int clusters : {1, 2}) {
      CAPTURE(clusters);
      const Scene scene = with_detector_tets(sphere_scene(clusters), 0.05);
      const auto frames = make_frames(scene, 16, press_poles);
      const SequenceReport rep = compare_with_brute(scene, frames);
      REQUIRE(rep.contact_frames == 1);
      CHECK(rep.orientation_culled + rep.clusters_skipped > 0);  // the detectors do cull
      CHECK(rep.rvbc_tests < rep.brute_tests);
    }
  }
  SECTION("A bent dumbbell (wedge tip), detectors inside tets.") {
    const Scene scene = with_detector_tets(dumbbell_scene(), 0.1);
    const auto frames = make_frames(
        scene, 16, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
    const SequenceReport rep = compare_with_brute(scene, frames);
    REQUIRE(rep.contact_frames == 1);
    CHECK(rep.orientation_culled > 0);
  }
}

TEST_CASE("Inverted and degenerate detector tets are handled conservatively",
          "[detector][collider][rvbc]") {
  // The runtime never rejects a step for its detector tets: any point trajectory used for all
  // triangles of a cluster keeps the culling sound (docs/runtime.md, "Detector points").
  for (double fling : {0.0, 3.0}) {
    for (int clusters : {1, 2}) {
      CAPTURE(fling, clusters);
      const Scene scene = with_detector_tets(sphere_scene(clusters), 0.05);
      auto frames = make_frames(scene, 16, press_poles);
      invert_detector_tets(scene, frames, fling);
      const SequenceReport rep = compare_with_brute(scene, frames);
      REQUIRE(rep.contact_frames == 1);
    }
    CAPTURE(fling);
    const Scene scene = with_detector_tets(dumbbell_scene(), 0.1);
    auto frames = make_frames(
        scene, 16, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
    invert_detector_tets(scene, frames, fling);
    const SequenceReport rep = compare_with_brute(scene, frames);
    REQUIRE(rep.contact_frames == 1);
  }
  SECTION("A step across the flat moment: the tet is degenerate inside the step.") {
    const Scene scene = with_detector_tets(sphere_scene(2), 0.05);
    auto frames = make_frames(scene, 3, press_poles);  // frame 1 is the flat tet
    invert_detector_tets(scene, frames, 0.0);
    Collider rvbc = collider_for(scene, ColliderMode::kRvbc);
    REQUIRE(rvbc.step(frames[0].data(), frames[1].data()) == ColliderStatus::kOk);
    REQUIRE(rvbc.step(frames[1].data(), frames[2].data()) == ColliderStatus::kOk);
    CHECK(rvbc.stats().triangles_positive > 0);  // a flat tet's point still classifies
  }
}

TEST_CASE("Random smooth deformations with detector points agree with brute force",
          "[detector][collider][rvbc]") {
  for (unsigned seed : {3u, 17u}) {
    CAPTURE(seed);
    const Scene scene = with_detector_tets(dumbbell_scene(), 0.1, {0.7, 0.1, 0.1, 0.1});
    const Waves waves(seed, 0.35);
    const auto frames = make_frames(scene, 12, waves);
    compare_with_brute(scene, frames);
  }
}

namespace {

/// Every frame: the collider's contact set equals brute force's exactly (same features, in
/// the same sorted order), as for the bvh mode. Returns the frames with a contact.
int require_brute_contact_set(const Scene& scene, const std::vector<std::vector<double>>& frames,
                              std::uint64_t* classified = nullptr) {
  Collider rvbc = collider_for(scene, ColliderMode::kRvbc);
  Collider brute = collider_for(scene, ColliderMode::kBrute);
  REQUIRE(rvbc.status() == ColliderStatus::kOk);
  int contact_frames = 0;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    CAPTURE(f);
    const StepAnswer b = answer(brute, frames[f].data(), frames[f + 1].data());
    const StepAnswer r = answer(rvbc, frames[f].data(), frames[f + 1].data());
    if (classified)
      *classified += rvbc.stats().triangles_positive + rvbc.stats().triangles_negative;
    CHECK(rvbc.stats().node_pairs_orientation_culled == 0);
    REQUIRE(r.any == b.any);
    REQUIRE(r.contacts.size() == b.contacts.size());
    for (std::size_t i = 0; i < b.contacts.size(); ++i) {
      CAPTURE(describe(b.contacts[i]));
      REQUIRE(same_feature(r.contacts[i], b.contacts[i]));
    }
    contact_frames += b.any ? 1 : 0;
  }
  return contact_frames;
}

}  // namespace

TEST_CASE("A body made only of overlap-only clusters gives exactly the brute-force contacts",
          "[detector][collider][overlap-only]") {
  std::uint64_t classified = 0;
  SECTION("Pressed sphere, 2 clusters, every step (also after the first contact).") {
    const Scene scene = with_cluster_flags(sphere_scene(2), format::kClusterOverlapOnly);
    CHECK(require_brute_contact_set(scene, make_frames(scene, 16, press_poles), &classified) > 1);
  }
  SECTION("Bent dumbbell, 3 clusters.") {
    const Scene scene = with_cluster_flags(dumbbell_scene(), format::kClusterOverlapOnly);
    const auto frames = make_frames(
        scene, 16, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
    CHECK(require_brute_contact_set(scene, frames, &classified) > 0);
  }
  SECTION("Detector points inside tets, flagged, with inverting tets.") {
    const Scene scene =
        with_cluster_flags(with_detector_tets(sphere_scene(1), 0.05), format::kClusterOverlapOnly);
    auto frames = make_frames(scene, 16, press_poles);
    invert_detector_tets(scene, frames, 3.0);
    CHECK(require_brute_contact_set(scene, frames, &classified) > 0);
  }
  CHECK(classified == 0);  // no triangle of a flagged cluster is ever classified
}

TEST_CASE("One overlap-only cluster beside classified ones agrees with brute force",
          "[detector][collider][overlap-only]") {
  format::Asset a = dumbbell_scene().asset.data();
  a.clusters[0].flags = format::kClusterOverlapOnly;  // one bell
  const Scene scene = load_scene(a, dumbbell_scene().surface_nodes);
  const auto frames = make_frames(
      scene, 16, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
  const SequenceReport rep = compare_with_brute(scene, frames);
  REQUIRE(rep.contact_frames == 1);
  // The other clusters are still culled by orientation.
  CHECK(rep.orientation_culled + rep.clusters_skipped > 0);
}

TEST_CASE("Only the detector nodes that are read must be finite", "[detector][collider][api]") {
  const Scene base = with_detector_tets(sphere_scene(2), 0.05);
  const std::size_t tet_node = base.rest.size() / 3 - 2;  // a node of cluster 1's detector tet
  std::vector<double> x1 = base.rest;
  x1[3 * tet_node + 1] = std::nan("");
  {
    Collider rvbc = collider_for(base, ColliderMode::kRvbc);
    CHECK(rvbc.step(base.rest.data(), x1.data()) == ColliderStatus::kNonFinite);
  }
  format::Asset a = base.asset.data();
  a.clusters[1].flags = format::kClusterOverlapOnly;
  const Scene flagged = load_scene(a, base.surface_nodes);
  Collider rvbc = collider_for(flagged, ColliderMode::kRvbc);
  CHECK(rvbc.step(flagged.rest.data(), x1.data()) == ColliderStatus::kOk);
}

TEST_CASE("The collider's triangle classes are classify_orientation's against the detector",
          "[detector][collider][rvbc][classify]") {
  // Classification runs two triangles at once (vector lanes) with a static error bound: each
  // class must be bitwise the scalar library function's, on pressing and inverted-detector
  // steps.
  for (double fling : {0.0, 3.0}) {
    for (int clusters : {1, 2}) {
      CAPTURE(fling, clusters);
      const Scene scene = with_detector_tets(sphere_scene(clusters), 0.05);
      auto frames = make_frames(scene, 6, press_poles);
      invert_detector_tets(scene, frames, fling);
      const format::Asset& a = scene.asset.data();
      Collider rvbc = collider_for(scene, ColliderMode::kRvbc);
      std::uint64_t definite = 0;
      for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
        CAPTURE(f);
        const double* x0 = frames[f].data();
        const double* x1 = frames[f + 1].data();
        REQUIRE(rvbc.step(x0, x1) == ColliderStatus::kOk);
        for (std::size_t t = 0; t < a.triangles.size(); ++t) {
          const format::Cluster& cl = a.clusters[a.triangle_cluster[t]];
          const auto o0 = format::detector_position(cl.detector, x0);
          const auto o1 = format::detector_position(cl.detector, x1);
          const auto& tri = a.triangles[t];
          auto p = [](const double* x, std::uint32_t n) { return x + std::size_t(n) * 3; };
          const Orientation expected =
              classify_orientation(o0.data(), p(x0, tri[0]), p(x0, tri[1]), p(x0, tri[2]),
                                   o1.data(), p(x1, tri[0]), p(x1, tri[1]), p(x1, tri[2]));
          REQUIRE(rvbc.triangle_class(t) == expected);
          definite += expected != Orientation::kUncertain;
        }
      }
      CHECK(definite > 0);
    }
  }
}
