// The collider against brute force on deforming closed surfaces (tests/runtime/support).

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "runtime/support/compare.hpp"
#include "runtime/support/motions.hpp"
#include "runtime/support/scenes.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using namespace tetseg;
using namespace tetseg::test;

TEST_CASE("Radial-view culling finds the first contact of a pressed sphere", "[collider][rvbc]") {
  for (int clusters : {1, 2}) {
    CAPTURE(clusters);
    const Scene scene = sphere_scene(clusters);
    const auto frames = make_frames(scene, 16, press_poles);
    const SequenceReport rep = compare_with_oracle(scene, frames);
    REQUIRE(rep.contact_frames == 1);
    CHECK(rep.rvbc_tests < rep.brute_tests);
  }
}

TEST_CASE("Radial-view culling finds the bells of a bent dumbbell touching, wedge tip included",
          "[collider][rvbc][wedge]") {
  const Scene scene = dumbbell_scene();
  const auto frames = make_frames(
      scene, 16, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
  const SequenceReport rep = compare_with_oracle(scene, frames);
  REQUIRE(rep.contact_frames == 1);
  CHECK(rep.orientation_culled > 0);
  CHECK(rep.rvbc_tests < rep.brute_tests);
  // The wedge-tip trap of the design note occurs here: an earliest contact whose feature pair
  // also lies in an orientation-culled triangle pair, found through a non-culled one.
  CHECK(rep.wedge_contacts > 0);
}

TEST_CASE("Radial-view culling finds the contacts of a twisted and bent pawn", "[collider][rvbc]") {
  const Scene scene = pawn_scene();
  const auto frames = make_frames(scene, 16, twist_bend);
  const SequenceReport rep = compare_with_oracle(scene, frames);
  REQUIRE(rep.contact_frames == 1);
  CHECK(rep.orientation_culled > 0);
}

TEST_CASE("Radial-view culling matches brute force under random smooth deformations",
          "[collider][rvbc]") {
  const unsigned seed = GENERATE(1u, 2u, 3u, 4u);
  const int shape = GENERATE(0, 1, 2);
  CAPTURE(seed, shape);
  const Scene scene = shape == 0 ? sphere_scene(2) : shape == 1 ? dumbbell_scene() : pawn_scene();
  const Waves waves(seed, 0.9);
  const auto frames = make_frames(scene, 12, waves);
  const SequenceReport rep = compare_with_oracle(scene, frames);
  CHECK(rep.contact_frames == 1);  // the waves do reach a contact
}

TEST_CASE("A drooping mushroom rim touching its base agrees with brute force",
          "[collider][rvbc][wedge]") {
  // Mushroom whose thin cap rim (a wedge: upper triangles positive, lower ones negative
  // against the detector) droops locally onto the conical base.
  const Surface s = mushroom(24);
  const Scene scene =
      make_scene(s, std::vector<std::uint32_t>(s.tris.size(), 0), {{0.0, 0.0, 0.3}});
  // The rim droops locally onto the conical base: its tip vertex is the first point to reach
  // the base face B.
  const auto frames = make_frames(scene, 16, RimDroop(s, 0.05));
  const SequenceReport rep = compare_with_oracle(scene, frames);
  REQUIRE(rep.contact_frames == 1);
  REQUIRE_FALSE(rep.first_contacts.empty());
}

TEST_CASE("Results do not depend on translation far from the origin or on scale",
          "[collider][numerics]") {
  const Scene scene = dumbbell_scene();
  const auto base = make_frames(
      scene, 12, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
  const SequenceReport untransformed = compare_with_oracle(scene, base);
  REQUIRE(untransformed.contact_frames == 1);
  const auto offset = GENERATE(P3{0, 0, 0}, P3{1e6, -1e6, 1e6});
  const double scale = GENERATE(1e-4, 1.0, 1e4);
  CAPTURE(offset[0], scale);
  const auto frames =
      transformed(base, scale, {offset[0] * scale, offset[1] * scale, offset[2] * scale});
  const SequenceReport rep = compare_with_oracle(scene, frames);
  REQUIRE(rep.contact_frames == 1);
  // The same step, the same first contacts, at the same time up to the rounding of the moved
  // positions (relative 1e-16 of an offset 1e6 times the object's size).
  CHECK(rep.frames_compared == untransformed.frames_compared);
  REQUIRE(rep.first_contacts.size() == untransformed.first_contacts.size());
  for (std::size_t i = 0; i < rep.first_contacts.size(); ++i) {
    CAPTURE(describe(untransformed.first_contacts[i]));
    CHECK(same_feature(rep.first_contacts[i], untransformed.first_contacts[i]));
    CHECK(rep.first_contacts[i].toi == Approx(untransformed.first_contacts[i].toi).margin(1e-6));
  }
}

TEST_CASE("Rigid motions and zero motion report no contact", "[collider][numerics]") {
  const Scene scene = pawn_scene();
  SECTION("A rigid rotation and translation of the whole object has no self-contact.") {
    const auto frames = make_frames(scene, 6, [](const P3& p, double t) {
      const double a = 2.0 * t;
      return P3{p[0] * std::cos(a) - p[2] * std::sin(a) + 3 * t, p[1] - 2 * t,
                p[0] * std::sin(a) + p[2] * std::cos(a)};
    });
    for (ColliderMode mode : {ColliderMode::kRvbc, ColliderMode::kBvh, ColliderMode::kBrute}) {
      ColliderOptions o;
      o.mode = mode;
      Collider c(scene.asset, o);
      for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
        REQUIRE(c.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
        CHECK_FALSE(any_ok(c));
        CHECK(contacts_ok(c, nullptr, 0).found == 0);
        CHECK_FALSE(earliest_ok(c).found);
      }
    }
  }
  SECTION("A step where nothing moves returns at once with no contact.") {
    Collider c(scene.asset);
    REQUIRE(c.step(scene.rest.data(), scene.rest.data()) == ColliderStatus::kOk);
    CHECK(c.stats().nothing_moved);
    CHECK_FALSE(any_ok(c));
    CHECK(c.stats().feature_tests == 0);
    CHECK(c.stats().node_pairs_visited == 0);
  }
  SECTION("A still cluster skips its intra-cluster work but contacts with it are still found.") {
    const Scene db = dumbbell_scene();
    // Only the top bell moves (bend pivot above the neck): bottom bell cluster is still.
    const auto frames = make_frames(
        db, 16, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, 0.6, 0.9, 0.6); });
    Collider c(db.asset);
    REQUIRE(c.step(frames[0].data(), frames[1].data()) == ColliderStatus::kOk);
    earliest_ok(c);
    CHECK(c.stats().clusters_skipped >= 1);
    const SequenceReport rep = compare_with_oracle(db, frames);
    CHECK(rep.contact_frames == 1);
  }
}

TEST_CASE("Near-degenerate motions agree with brute force", "[collider][numerics]") {
  const Scene scene = sphere_scene(2);
  SECTION("Tiny motions of 1e-12 relative size give the same answers.") {
    const auto frames = make_frames(scene, 4, [](const P3& p, double t) {
      return P3{p[0] + 1e-12 * t * p[1], p[1], p[2] - 1e-12 * t};
    });
    const SequenceReport rep = compare_with_oracle(scene, frames);
    CHECK(rep.contact_frames == 0);
  }
  SECTION("Sliding every node tangentially along the sphere gives no contact.") {
    const auto frames = make_frames(scene, 5, [](const P3& p, double t) {
      const double a = 0.3 * t;  // rotation about z keeps the sphere on itself
      return P3{p[0] * std::cos(a) - p[1] * std::sin(a), p[0] * std::sin(a) + p[1] * std::cos(a),
                p[2]};
    });
    const SequenceReport rep = compare_with_oracle(scene, frames);
    CHECK(rep.contact_frames == 0);
  }
}

TEST_CASE("Invalid step input is rejected with a status", "[collider][api]") {
  const Scene scene = sphere_scene(1);
  Collider c(scene.asset);
  std::vector<double> x = scene.rest;
  CHECK(c.step(x.data(), x.data(), x.size() - 3) == ColliderStatus::kSizeMismatch);
  CHECK(c.step(nullptr, x.data()) == ColliderStatus::kNullInput);
  x[4] = std::nan("");
  CHECK(c.step(scene.rest.data(), x.data()) == ColliderStatus::kNonFinite);
  bool hit = true;
  CHECK(c.any_collision(hit) == ColliderStatus::kNoStep);
  CHECK_FALSE(hit);
  ContactsResult r;
  CHECK(c.contacts(nullptr, 0, r) == ColliderStatus::kNoStep);
  x[4] = INFINITY;
  CHECK(c.step(x.data(), scene.rest.data()) == ColliderStatus::kNonFinite);
}

TEST_CASE("Contacts are truncated to the caller's capacity and the count is reported",
          "[collider][api]") {
  const Scene scene = sphere_scene(1);
  const auto frames = make_frames(scene, 3, press_poles);  // one big step through the centre
  Collider c(scene.asset);
  REQUIRE(c.step(frames[0].data(), frames[2].data()) == ColliderStatus::kOk);
  const ContactsResult all = contacts_ok(c, nullptr, 0);
  REQUIRE(all.found > 3);
  std::vector<Contact> buf(2);
  const ContactsResult r = contacts_ok(c, buf.data(), buf.size());
  CHECK(r.found == all.found);
  CHECK(r.written == 2);
  CHECK(r.truncated());
  const EarliestContact e = earliest_ok(c);
  REQUIRE(e.found);
  std::vector<Contact> full(all.found);
  const ContactsResult f = contacts_ok(c, full.data(), full.size());
  REQUIRE_FALSE(f.truncated());
  CHECK(full.front().toi == e.contact.toi);
  CHECK(same_feature(full.front(), e.contact));
}

TEST_CASE("A self-intersecting start state is reported", "[collider][rest]") {
  const Scene scene = sphere_scene(2);
  Collider c(scene.asset);
  const RestCheck clean = c.check_rest_intersection(scene.rest.data(), scene.rest.size());
  REQUIRE(clean.status == ColliderStatus::kOk);
  CHECK_FALSE(clean.intersecting);
  const auto frames = make_frames(scene, 2, press_poles);  // poles pushed through each other
  const RestCheck bad = c.check_rest_intersection(frames[1].data(), frames[1].size());
  REQUIRE(bad.status == ColliderStatus::kOk);
  CHECK(bad.intersecting);
  ColliderOptions o;
  o.check_first_step = true;
  Collider d(scene.asset, o);
  REQUIRE(d.step(frames[1].data(), frames[1].data()) == ColliderStatus::kOk);
  CHECK(d.rest_intersection().intersecting);
}

TEST_CASE("Degenerate chain BVHs as deep as the cluster is large are traversed correctly",
          "[collider][api]") {
  const Surface s = dumbbell(12, 16);
  std::vector<std::uint32_t> cluster_of(s.tris.size());
  for (std::size_t t = 0; t < s.tris.size(); ++t)
    cluster_of[t] = s.verts[s.tris[t][0]][2] > 0 ? 1 : 0;
  const Scene chain = make_scene(s, cluster_of, {{0, 0, -1.6}, {0, 0, 1.6}}, 0);
  const Scene split = make_scene(s, cluster_of, {{0, 0, -1.6}, {0, 0, 1.6}}, 2);
  const auto frames = make_frames(
      chain, 12, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
  const SequenceReport rep = compare_with_oracle(chain, frames);
  CHECK(rep.contact_frames == 1);
  // Same contacts as with well-formed BVHs, step by step.
  Collider a(chain.asset), b(split.asset);
  std::vector<Contact> ca(1 << 14), cb(1 << 14);
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    REQUIRE(a.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    REQUIRE(b.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    const ContactsResult ra = contacts_ok(a, ca.data(), ca.size());
    const ContactsResult rb = contacts_ok(b, cb.data(), cb.size());
    REQUIRE(ra.found == rb.found);
    for (std::size_t i = 0; i < ra.written; ++i) CHECK(same_feature(ca[i], cb[i]));
  }
}

TEST_CASE("A minimum separation finds contacts no later and no fewer than exact contact",
          "[collider][api]") {
  const Scene scene = dumbbell_scene();
  const auto frames = make_frames(
      scene, 12, [](const P3& p, double t) { return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0); });
  for (ColliderMode mode : {ColliderMode::kBvh, ColliderMode::kBrute}) {
    CAPTURE(to_string(mode));
    ColliderOptions exact_options, near_options;
    exact_options.mode = near_options.mode = mode;
    near_options.ccd.min_separation = 0.02;
    Collider exact(scene.asset, exact_options), near(scene.asset, near_options);
    std::vector<Contact> ce(1 << 15), cn(1 << 15);
    bool near_earlier = false;
    for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
      REQUIRE(exact.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
      REQUIRE(near.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
      const ContactsResult re = contacts_ok(exact, ce.data(), ce.size());
      const ContactsResult rn = contacts_ok(near, cn.data(), cn.size());
      REQUIRE_FALSE(rn.truncated());
      for (std::size_t i = 0; i < re.written; ++i) {
        const bool found = std::any_of(cn.begin(), cn.begin() + rn.written,
                                       [&](const Contact& c) { return same_feature(c, ce[i]); });
        CHECK(found);
      }
      if (re.found > 0) {
        CHECK(earliest_ok(near).contact.toi <= earliest_ok(exact).contact.toi);
        break;
      }
      near_earlier = near_earlier || rn.found > 0;
    }
    CHECK(near_earlier);  // the near contact shows up at least one step before the exact one
  }
  ColliderMode parsed = ColliderMode::kBrute;
  CHECK(parse_collider_mode("rvbc", parsed));
  CHECK(parsed == ColliderMode::kRvbc);
  CHECK_FALSE(parse_collider_mode("fast", parsed));
  CHECK_FALSE(parse_collider_mode(nullptr, parsed));
}

TEST_CASE("Poles meeting head on: every brute-force contact at the earliest toi is found",
          "[collider][rvbc][closure]") {
  // Centred dents: the two poles (vertices) meet exactly, so dozens of vertex-face and
  // edge-edge pairs of the two pole fans touch at one point at the same time, most of them in
  // triangle pairs that orientation culls. The contact closure must recover them.
  for (int clusters : {1, 2}) {
    CAPTURE(clusters);
    const Scene scene = sphere_scene(clusters);
    const auto frames = make_frames(scene, 16, press_poles_head_on);
    const SequenceReport rep = compare_with_oracle(scene, frames);
    REQUIRE(rep.contact_frames == 1);
    CHECK(rep.first_contacts.size() > 8);
    CHECK(rep.closure_pairs > 0);
  }
}
