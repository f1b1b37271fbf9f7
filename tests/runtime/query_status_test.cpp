// Every collider query reports a status, and a failure is never an answer: null positions,
// size mismatch, NaN, no step and a forced traversal overflow each give their own status with
// an empty answer, distinguishable from "no contact" (kOk with nothing found).

#include <catch2/catch.hpp>
#include <cmath>

#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using namespace tetseg;
using namespace tetseg::test;

namespace {

/// Runs the three queries and requires each to return `expected` (answers must be empty
/// unless kOk).
void require_queries(Collider& c, ColliderStatus expected) {
  bool hit = true;
  CHECK(c.any_collision(hit) == expected);
  if (expected != ColliderStatus::kOk) CHECK_FALSE(hit);
  EarliestContact e;
  e.found = true;
  CHECK(c.earliest_toi(e) == expected);
  if (expected != ColliderStatus::kOk) CHECK_FALSE(e.found);
  ContactsResult r;
  r.found = 7;
  CHECK(c.contacts(nullptr, 0, r) == expected);
  if (expected != ColliderStatus::kOk) CHECK(r.found == 0);
}

}  // namespace

TEST_CASE("Collider queries report failures as statuses, never as no contact", "[collider][api]") {
  const Scene scene = make_axial_scene(sphere(1.0, 20, 11), {0.0}, {-0.45, 0.45});
  const auto frames = make_frames(scene, 3, press_poles);  // frame 0 -> 2 passes the poles
  const std::vector<double>& x0 = frames[0];
  const std::vector<double>& x1 = frames[2];
  // Every mode runs every case on a fresh collider (plain blocks: a SECTION inside the loop
  // would run for the first mode only).
  for (ColliderMode mode :
       {ColliderMode::kRvbc, ColliderMode::kBvh, ColliderMode::kBrute, ColliderMode::kCone}) {
    CAPTURE(to_string(mode));
    ColliderOptions o;
    o.mode = mode;
    {
      INFO("No step yet");
      Collider c(scene.asset, o);
      REQUIRE(c.status() == ColliderStatus::kOk);
      require_queries(c, ColliderStatus::kNoStep);
    }
    {
      INFO("A rejected step drops the previous one");
      Collider c(scene.asset, o);
      REQUIRE(c.status() == ColliderStatus::kOk);
      REQUIRE(c.step(x0.data(), x1.data()) == ColliderStatus::kOk);
      require_queries(c, ColliderStatus::kOk);
      CHECK(c.step(nullptr, x1.data()) == ColliderStatus::kNullInput);
      require_queries(c, ColliderStatus::kNoStep);
      REQUIRE(c.step(x0.data(), x1.data()) == ColliderStatus::kOk);
      CHECK(c.step(x0.data(), x1.data(), x0.size() - 3) == ColliderStatus::kSizeMismatch);
      require_queries(c, ColliderStatus::kNoStep);
      std::vector<double> bad = x1;
      bad[4] = std::nan("");
      REQUIRE(c.step(x0.data(), x1.data()) == ColliderStatus::kOk);
      CHECK(c.step(x0.data(), bad.data()) == ColliderStatus::kNonFinite);
      require_queries(c, ColliderStatus::kNoStep);
      bad[4] = -INFINITY;
      CHECK(c.step(bad.data(), x1.data()) == ColliderStatus::kNonFinite);
      require_queries(c, ColliderStatus::kNoStep);
    }
    {
      INFO("The contacting step is found; a still step is an honest no contact");
      Collider c(scene.asset, o);
      REQUIRE(c.status() == ColliderStatus::kOk);
      REQUIRE(c.step(x0.data(), x1.data()) == ColliderStatus::kOk);
      bool hit = false;
      REQUIRE(c.any_collision(hit) == ColliderStatus::kOk);
      CHECK(hit);
      REQUIRE(c.step(x0.data(), x0.data()) == ColliderStatus::kOk);
      REQUIRE(c.any_collision(hit) == ColliderStatus::kOk);
      CHECK_FALSE(hit);
    }
  }
  SECTION("A forced traversal overflow is kOverflow, not no contact") {
    for (ColliderMode mode : {ColliderMode::kRvbc, ColliderMode::kBvh, ColliderMode::kCone}) {
      CAPTURE(to_string(mode));
      ColliderOptions o;
      o.mode = mode;
      o.traversal_stack = 1;
      Collider c(scene.asset, o);
      REQUIRE(c.step(x0.data(), x1.data()) == ColliderStatus::kOk);
      require_queries(c, ColliderStatus::kOverflow);
      std::vector<Contact> buffer(16);
      ContactsResult r;
      CHECK(c.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOverflow);
      CHECK(r.written == 0);
      CHECK(c.check_rest_intersection(x0.data(), x0.size()).status == ColliderStatus::kOverflow);
    }
  }
}
