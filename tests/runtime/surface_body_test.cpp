// Surface bodies (asset format 1.2) in the runtime: detectors given by surface weights or
// carried by bones. The collider's contacts against the independent brute-force oracle
// (compare.hpp) under smooth deformations, bending, and motions that carry a detector outside
// its part; bone-carried detectors at any positions, right or wrong; the API's statuses; scenes.

#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "runtime/support/compare.hpp"
#include "runtime/support/motions.hpp"
#include "runtime/support/off.hpp"
#include "runtime/support/scenes.hpp"
#include "tetseg/format/skin.hpp"
#include "tetseg/runtime/scene.hpp"
#include "tetseg/testing/allocation_probe.hpp"
#include "tetseg/testing/surface_bodies.hpp"

// Not `using namespace tetseg`: `Scene` is the test scene here (the runtime's is tetseg::Scene).
using namespace tetseg::test;
using tetseg::BodyShape;
using tetseg::Collider;
using tetseg::ColliderMode;
using tetseg::ColliderOptions;
using tetseg::ColliderStatus;
using tetseg::Contact;
using tetseg::ContactsResult;
namespace format = tetseg::format;

namespace {

Deformation bend_dumbbell() {
  return [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); };
}

/// Moves every term vertex of every cluster's detector (kSurfaceWeights) `distance` along its
/// outward direction from the origin by frame t (a spike: the detector leaves the body).
void spike_detector_vertices(const Scene& scene, std::vector<std::vector<double>>& frames,
                             double distance) {
  const format::Asset& a = scene.asset.data();
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const double t = double(f) / double(frames.size() - 1);
    std::vector<std::uint8_t> moved(a.node_count, 0);
    for (const format::DetectorTerm& term : a.detector_terms) {
      if (moved[term.index]) continue;
      moved[term.index] = 1;
      double* p = frames[f].data() + 3 * std::size_t(term.index);
      const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      for (int k = 0; k < 3; ++k) p[k] += t * distance * p[k] / r;
    }
  }
}

/// Detector positions of a kBones body per frame (clusters x 3): `place(c, rest, t)`.
using Placement = std::function<P3(std::size_t, const P3&, double)>;
std::vector<std::vector<double>> detector_frames(const Scene& scene, std::size_t frames,
                                                 const Placement& place) {
  const format::Asset& a = scene.asset.data();
  std::vector<std::vector<double>> out(frames);
  for (std::size_t f = 0; f < frames; ++f) {
    const double t = frames > 1 ? double(f) / double(frames - 1) : 0.0;
    for (std::size_t c = 0; c < a.clusters.size(); ++c) {
      const P3 p = place(c, a.clusters[c].detector_rest, t);
      out[f].insert(out[f].end(), p.begin(), p.end());
    }
  }
  return out;
}

/// The rvbc collider of a kBones body, stepped with the given detector positions, against the
/// oracle on every step up to the first contact (as compare_with_oracle). Returns the report.
SequenceReport compare_bones_with_oracle(const Scene& scene,
                                         const std::vector<std::vector<double>>& frames,
                                         const std::vector<std::vector<double>>& detectors) {
  Collider rvbc = collider_for(scene, ColliderMode::kRvbc);
  REQUIRE(rvbc.status() == ColliderStatus::kOk);
  SequenceReport rep;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    CAPTURE(f);
    const double* x0 = frames[f].data();
    const double* x1 = frames[f + 1].data();
    REQUIRE(rvbc.set_detector_positions(detectors[f].data(), detectors[f + 1].data(),
                                        detectors[f].size()) == ColliderStatus::kOk);
    const StepTruth truth = step_truth(scene, x0, x1);
    const StepAnswer r = answer(rvbc, x0, x1);
    rep.orientation_culled += rvbc.stats().node_pairs_orientation_culled;
    rep.clusters_skipped += rvbc.stats().clusters_skipped;
    ++rep.frames_compared;
    require_matches_oracle(r, truth, Expect::kEarliestContacts);
    if (!truth.required.empty()) {
      ++rep.contact_frames;
      break;
    }
  }
  return rep;
}

}  // namespace

TEST_CASE("Surface bodies: the helper builds valid surface assets", "[surface][api]") {
  const Scene tet = dumbbell_scene();
  const Scene w = as_weighted_surface_body(tet);
  const Scene b = as_bone_surface_body(tet, 3);
  for (const Scene* s : {&w, &b}) {
    const format::Asset& a = s->asset.data();
    CHECK(a.body_kind == format::BodyKind::kSurface);
    CHECK(a.node_count == tet.surface_nodes);
    CHECK(a.triangles == tet.asset.data().triangles);
    CHECK(format::minor_version_needed(a) == 2);
    const auto shape = BodyShape::from_asset(s->asset);
    REQUIRE(shape);
    CHECK(shape->has_clusters());
    CHECK(shape->node_count() == tet.surface_nodes);
    CHECK(shape->triangle_count() == a.triangles.size());
  }
  CHECK(w.asset.data().detector_form == format::DetectorForm::kSurfaceWeights);
  CHECK(b.asset.data().detector_form == format::DetectorForm::kBones);
}

TEST_CASE("Surface bodies with weighted detectors find the contacts brute force finds",
          "[surface][collider][rvbc]") {
  SECTION("A pressed sphere, 1 and 2 clusters.") {
    for (int clusters : {1, 2}) {
      CAPTURE(clusters);
      const Scene scene = as_weighted_surface_body(sphere_scene(clusters), 6);
      const SequenceReport rep = compare_with_oracle(scene, make_frames(scene, 16, press_poles));
      REQUIRE(rep.contact_frames == 1);
      CHECK(rep.orientation_culled + rep.clusters_skipped > 0);  // the detectors do cull
      CHECK(rep.rvbc_tests < rep.brute_tests);
    }
  }
  SECTION("A bent dumbbell (wedge tip).") {
    const Scene scene = as_weighted_surface_body(dumbbell_scene());
    const SequenceReport rep = compare_with_oracle(scene, make_frames(scene, 16, bend_dumbbell()));
    REQUIRE(rep.contact_frames == 1);
    CHECK(rep.orientation_culled > 0);
  }
  SECTION("Random smooth deformations.") {
    for (unsigned seed : {3u, 17u, 29u}) {
      CAPTURE(seed);
      const Scene scene = as_weighted_surface_body(dumbbell_scene(), 3);
      const auto frames = make_frames(scene, 12, Waves(seed, 0.35));
      CHECK(compare_with_oracle(scene, frames).contact_frames == 1);
    }
  }
  SECTION("One cluster: every contact is inside the cluster, where orientation culls.") {
    const Surface bell = dumbbell(16, 26);
    const Scene tet =
        make_scene(bell, std::vector<std::uint32_t>(bell.tris.size(), 0), {{0, 0, 0}});
    for (std::uint32_t terms : {2u, 8u}) {
      CAPTURE(terms);
      const Scene scene = as_weighted_surface_body(tet, terms);
      const SequenceReport rep =
          compare_with_oracle(scene, make_frames(scene, 16, bend_dumbbell()));
      REQUIRE(rep.contact_frames == 1);
      CHECK(rep.orientation_culled + rep.clusters_skipped > 0);
      for (unsigned seed : {3u, 17u}) {
        CAPTURE(seed);
        const auto frames = make_frames(scene, 12, Waves(seed, 0.35));
        CHECK(compare_with_oracle(scene, frames).contact_frames == 1);
      }
    }
  }
  SECTION("A twisted, bent pawn with single-vertex detectors.") {
    const Scene scene = as_weighted_surface_body(pawn_scene(), 1);
    const auto frames = make_frames(scene, 16, twist_bend);
    CHECK(compare_with_oracle(scene, frames).frames_compared > 0);
  }
}

TEST_CASE("A detector that leaves its part costs only culling, never a contact",
          "[surface][collider][rvbc]") {
  SECTION("The detector's vertices spike far out of the body during the motion.") {
    for (double distance : {0.5, 4.0}) {
      CAPTURE(distance);
      const Scene scene = as_weighted_surface_body(sphere_scene(2), 3);
      auto frames = make_frames(scene, 16, press_poles);
      spike_detector_vertices(scene, frames, distance);
      CHECK(compare_with_oracle(scene, frames).contact_frames == 1);
    }
    const Scene scene = as_weighted_surface_body(dumbbell_scene(), 2);
    auto frames = make_frames(scene, 16, bend_dumbbell());
    spike_detector_vertices(scene, frames, 3.0);
    CHECK(compare_with_oracle(scene, frames).contact_frames == 1);
  }
  SECTION("Every detector is made of another part's vertices, from rest on.") {
    for (std::uint32_t shift : {1u, 2u}) {
      CAPTURE(shift);
      const Scene scene = as_weighted_surface_body(dumbbell_scene(), 4, shift);
      CHECK(compare_with_oracle(scene, make_frames(scene, 16, bend_dumbbell())).contact_frames ==
            1);
      const auto waves = make_frames(scene, 12, Waves(5 + shift, 0.35));
      CHECK(compare_with_oracle(scene, waves).contact_frames == 1);
    }
  }
}

TEST_CASE("Bone-carried detectors are exact at any positions, right or wrong",
          "[surface][collider][rvbc][bones]") {
  const Scene tet = dumbbell_scene();
  const Scene scene = as_bone_surface_body(tet, 3);
  const auto frames = make_frames(scene, 16, bend_dumbbell());
  std::mt19937 rng(2026);
  auto u = [&] { return (rng() / 4294967296.0) * 2 - 1; };
  SECTION("Right: each detector moved by the same bend as the surface.") {
    const auto det =
        detector_frames(scene, frames.size(), [](std::size_t, const P3& rest, double t) {
          return bend_about_x(rest, t, 2.6, -0.5, 0.5, 0.0);
        });
    const SequenceReport rep = compare_bones_with_oracle(scene, frames, det);
    REQUIRE(rep.contact_frames == 1);
    CHECK(rep.orientation_culled > 0);  // a right pose culls
  }
  SECTION("Wrong: the skeleton stays at rest while the body bends.") {
    const auto det = detector_frames(scene, frames.size(),
                                     [](std::size_t, const P3& rest, double) { return rest; });
    CHECK(compare_bones_with_oracle(scene, frames, det).contact_frames == 1);
  }
  SECTION("Wrong: detectors swapped between clusters and thrown far outside.") {
    const format::Asset& a = scene.asset.data();
    const auto det = detector_frames(scene, frames.size(), [&](std::size_t c, const P3&, double t) {
      const P3 other = a.clusters[(c + 1) % a.clusters.size()].detector_rest;
      return P3{other[0] + 5 * t, other[1] - 3 * t * t, other[2] + 2 * std::sin(7 * t)};
    });
    CHECK(compare_bones_with_oracle(scene, frames, det).contact_frames == 1);
  }
  SECTION("Wrong: random positions, new every frame.") {
    const auto det = detector_frames(scene, frames.size(), [&](std::size_t, const P3&, double) {
      return P3{3 * u(), 3 * u(), 3 * u()};
    });
    CHECK(compare_bones_with_oracle(scene, frames, det).contact_frames == 1);
  }
  SECTION("Skinned: skinned_detector_positions with each bone's rigid transform of the bend.") {
    // Bone b follows the bend's rotation at the height of the clusters it carries first: the
    // matrices of a skinned character, as an application would pass them.
    const format::Asset& a = scene.asset.data();
    std::vector<std::vector<double>> det(frames.size(), std::vector<double>(3 * a.clusters.size()));
    for (std::size_t f = 0; f < frames.size(); ++f) {
      const double t = double(f) / double(frames.size() - 1);
      std::vector<double> m(12 * a.bone_names.size(), 0.0);
      for (std::size_t b = 0; b < a.bone_names.size(); ++b) {
        const double z = a.clusters[b].detector_rest[2];
        const double angle = t * 2.6 * smoothstep(z, -0.5, 0.5);
        const double c = std::cos(angle), s = std::sin(angle);
        const double rot[12] = {1, 0, 0, 0, 0, c, -s, 0, 0, s, c, 0};
        std::copy(rot, rot + 12, m.begin() + 12 * b);
      }
      format::skinned_detector_positions(a, m.data(), det[f].data());
    }
    CHECK(compare_bones_with_oracle(scene, frames, det).contact_frames == 1);
  }
}

TEST_CASE("Surface bodies on deformed real meshes match brute force",
          "[surface][collider][rvbc][mesh]") {
  const std::string name = GENERATE(as<std::string>{}, "eight", "joint");
  CAPTURE(name);
  Surface s;
  if (!read_demo_surface(name, s)) return;
  const Scene scene = as_weighted_surface_body(slab_scene(s, 5), 5);
  const double size = bounding_diagonal(s);
  Waves waves(11, 0.2 * size, 6.0 / size);
  const SequenceReport rep = compare_with_oracle(scene, make_frames(scene, 10, waves));
  CHECK(rep.contact_frames == 1);
  CHECK(rep.rvbc_tests <= rep.brute_tests);
}

TEST_CASE("Surface bodies: statuses of detector inputs", "[surface][collider][api]") {
  const Scene tet = sphere_scene(2);
  const Scene bones = as_bone_surface_body(tet, 2);
  const Scene weights = as_weighted_surface_body(tet, 3);
  const std::vector<double>& x = bones.rest;
  std::vector<double> d0(6), d1(6);
  for (std::size_t c = 0; c < 2; ++c)
    for (int k = 0; k < 3; ++k)
      d0[3 * c + k] = d1[3 * c + k] = bones.asset.data().clusters[c].detector_rest[k];
  SECTION("kBones: rvbc needs the detector positions; other modes and the rest check do not.") {
    Collider rvbc(bones.asset);
    CHECK(rvbc.step(x.data(), x.data()) == ColliderStatus::kNullInput);
    CHECK(rvbc.check_rest_intersection(x.data(), x.size()).status == ColliderStatus::kOk);
    CHECK(rvbc.set_detector_positions(d0.data(), d1.data(), 5) == ColliderStatus::kSizeMismatch);
    CHECK(rvbc.set_detector_positions(d0.data(), nullptr, 6) == ColliderStatus::kOk);
    CHECK(rvbc.step(x.data(), x.data()) == ColliderStatus::kNullInput);
    CHECK(rvbc.set_detector_positions(d0.data(), d1.data(), 6) == ColliderStatus::kOk);
    CHECK(rvbc.step(x.data(), x.data()) == ColliderStatus::kOk);
    d1[4] = std::nan("");
    CHECK(rvbc.step(x.data(), x.data()) == ColliderStatus::kNonFinite);
    bool hit = true;
    CHECK(rvbc.any_collision(hit) == ColliderStatus::kNoStep);
    d1[4] = INFINITY;
    CHECK(rvbc.step(x.data(), x.data()) == ColliderStatus::kNonFinite);
    d1[4] = d0[4];
    CHECK(rvbc.step(x.data(), x.data()) == ColliderStatus::kOk);
    for (ColliderMode mode : {ColliderMode::kBvh, ColliderMode::kBrute, ColliderMode::kCone}) {
      ColliderOptions o;
      o.mode = mode;
      Collider other(bones.asset, o);
      CHECK(other.step(x.data(), x.data()) == ColliderStatus::kOk);
    }
  }
  SECTION("kBones: an overlap-only cluster's entries are not read.") {
    format::Asset a = bones.asset.data();
    a.clusters[1].flags = format::kClusterOverlapOnly;
    const Scene flagged = load_scene(a, bones.surface_nodes);
    Collider rvbc(flagged.asset);
    d0[3] = d1[5] = std::nan("");
    REQUIRE(rvbc.set_detector_positions(d0.data(), d1.data(), 6) == ColliderStatus::kOk);
    CHECK(rvbc.step(x.data(), x.data()) == ColliderStatus::kOk);
  }
  SECTION("Other forms refuse detector positions.") {
    Collider w(weights.asset);
    CHECK(w.set_detector_positions(d0.data(), d1.data(), 6) == ColliderStatus::kInvalidArgument);
    Collider t(tet.asset);
    CHECK(t.set_detector_positions(d0.data(), d1.data(), 6) == ColliderStatus::kInvalidArgument);
    CHECK(w.step(x.data(), x.data()) == ColliderStatus::kOk);
  }
  SECTION("kSurfaceWeights: a NaN in a term vertex is rejected in every mode.") {
    const std::uint32_t term = weights.asset.data().detector_terms[1].index;
    std::vector<double> bad = x;
    bad[3 * term + 2] = std::nan("");
    for (ColliderMode mode : {ColliderMode::kRvbc, ColliderMode::kBvh}) {
      ColliderOptions o;
      o.mode = mode;
      Collider c(weights.asset, o);
      CHECK(c.step(x.data(), bad.data()) == ColliderStatus::kNonFinite);
    }
  }
}

TEST_CASE("Surface bodies in a scene: self contacts equal the collider's", "[surface][scene]") {
  const Scene tet = dumbbell_scene();
  const Scene weights = as_weighted_surface_body(tet, 4);
  const Scene bones = as_bone_surface_body(tet, 3);
  const auto frames = make_frames(weights, 16, bend_dumbbell());
  const auto det = detector_frames(bones, frames.size(), [](std::size_t, const P3& rest, double t) {
    return bend_about_x(rest, t, 2.6, -0.5, 0.5, 0.0);
  });
  tetseg::Scene scene;
  std::uint32_t wid = 0, bid = 0;
  REQUIRE(scene.add_body(BodyShape::from_asset(weights.asset), {}, &wid) == ColliderStatus::kOk);
  REQUIRE(scene.add_body(BodyShape::from_asset(bones.asset), {}, &bid) == ColliderStatus::kOk);
  REQUIRE(scene.set_pair_enabled(wid, bid, false) == ColliderStatus::kOk);
  Collider cw(weights.asset);
  Collider cb(bones.asset);
  CHECK(scene.set_detector_positions(wid, det[0].data(), det[1].data(), det[0].size()) ==
        ColliderStatus::kInvalidArgument);
  CHECK(scene.set_detector_positions(7, det[0].data(), det[1].data(), det[0].size()) ==
        ColliderStatus::kInvalidArgument);
  // Positions set, detectors not yet: the bones body refuses the step.
  for (std::uint32_t id : {wid, bid})
    REQUIRE(scene.set_positions(id, frames[0].data(), frames[1].data(), frames[0].size()) ==
            ColliderStatus::kOk);
  CHECK(scene.step() == ColliderStatus::kNullInput);
  std::size_t total = 0;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    CAPTURE(f);
    for (std::uint32_t id : {wid, bid})
      REQUIRE(scene.set_positions(id, frames[f].data(), frames[f + 1].data(), frames[f].size()) ==
              ColliderStatus::kOk);
    REQUIRE(scene.set_detector_positions(bid, det[f].data(), det[f + 1].data(), det[f].size()) ==
            ColliderStatus::kOk);
    REQUIRE(scene.step() == ColliderStatus::kOk);
    REQUIRE(cb.set_detector_positions(det[f].data(), det[f + 1].data(), det[f].size()) ==
            ColliderStatus::kOk);
    const StepAnswer aw = answer(cw, frames[f].data(), frames[f + 1].data());
    const StepAnswer ab = answer(cb, frames[f].data(), frames[f + 1].data());
    std::vector<Contact> buffer(1 << 14);
    ContactsResult r;
    REQUIRE(scene.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOk);
    buffer.resize(r.written);
    std::vector<Contact> expected;
    for (Contact c : aw.contacts) expected.push_back(c);
    for (Contact c : ab.contacts) {
      c.bodies = {bid, bid};
      expected.push_back(c);
    }
    std::sort(expected.begin(), expected.end(), tetseg::contact_less);
    REQUIRE(buffer.size() == expected.size());
    for (std::size_t i = 0; i < buffer.size(); ++i) {
      CHECK(buffer[i].nodes == expected[i].nodes);
      CHECK(buffer[i].bodies == expected[i].bodies);
      CHECK(buffer[i].toi == expected[i].toi);
    }
    total += buffer.size();
    if (!aw.contacts.empty()) break;  // after the first contact the start may intersect
  }
  CHECK(total > 0);
}

TEST_CASE("Surface bodies: steps and queries allocate nothing", "[surface][alloc]") {
  const Scene tet = dumbbell_scene();
  const Scene weights = as_weighted_surface_body(tet, 4);
  const Scene bones = as_bone_surface_body(tet, 3);
  const auto frames = make_frames(weights, 16, bend_dumbbell());
  const auto det = detector_frames(bones, frames.size(),
                                   [](std::size_t, const P3& rest, double) { return rest; });
  std::vector<Contact> buffer(256);
  for (const Scene* s : {&weights, &bones}) {
    Collider c(s->asset);
    REQUIRE(c.status() == ColliderStatus::kOk);
    std::size_t contacts = 0;
    for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
      AllocationProbe counter;
      if (s == &bones)
        REQUIRE(c.set_detector_positions(det[f].data(), det[f + 1].data(), det[f].size()) ==
                ColliderStatus::kOk);
      REQUIRE(c.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
      any_ok(c);
      earliest_ok(c);
      contacts += contacts_ok(c, buffer.data(), buffer.size()).found;
      CHECK(counter.count() == 0);
    }
    CHECK(contacts > 0);
  }
}
