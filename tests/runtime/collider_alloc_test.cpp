// A collider step and its queries allocate nothing (counted by the test executable's
// replacement operator new, testing/src/allocation_probe.cpp); OpenMP results equal serial.

#include <catch2/catch.hpp>
#include <random>

#include "runtime/support/queries.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/allocation_probe.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using namespace tetseg;
using namespace tetseg::test;

namespace {
P3 squash(const P3& p, double t) {
  const double w = std::exp(-(p[0] * p[0] + p[1] * p[1]) / 0.3);
  const double dz = (p[2] > 0 ? -1.0 : 1.0) * 1.4 * t * w * std::min(1.0, std::fabs(p[2]) * 4);
  return {p[0] + 0.1 * dz + 0.05 * t * std::sin(5 * p[2]), p[1] + 0.05 * dz, p[2] + dz};
}
}  // namespace

TEST_CASE("A step and its queries allocate nothing", "[collider][alloc]") {
  const Scene scene = make_axial_scene(sphere(1.0, 24, 13), {0.0}, {-0.4, 0.4});
  const auto frames = make_frames(scene, 6, squash);
  std::vector<Contact> buffer(4096);
  for (ColliderMode mode : {ColliderMode::kRvbc, ColliderMode::kBvh, ColliderMode::kBrute}) {
    CAPTURE(to_string(mode));
    ColliderOptions o;
    o.mode = mode;
    o.check_first_step = true;
    Collider c(scene.asset, o);
    REQUIRE(c.status() == ColliderStatus::kOk);
    std::size_t contacts = 0;
    for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
      AllocationProbe counter;
      REQUIRE(c.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
      any_ok(c);
      earliest_ok(c);
      contacts += contacts_ok(c, buffer.data(), buffer.size()).found;
      c.check_rest_intersection(frames[f].data(), frames[f].size());
      CHECK(counter.count() == 0);
    }
    CHECK(contacts > 0);  // the sequence exercises the contact paths
  }
}

TEST_CASE("OpenMP results are identical to serial results", "[collider][openmp]") {
  // Large enough (> 4096 surface nodes) for the parallel refit/classification loops to engage;
  // traversal runs in parallel for queries without a caller buffer.
  const Scene scene = make_axial_scene(sphere(1.0, 96, 60), {-0.3, 0.3}, {-0.6, 0.0, 0.6});
  const auto frames =
      make_frames(scene, 4, [](const P3& p, double t) { return squash(p, 0.75 * t); });
  const ColliderMode mode = ColliderMode::kRvbc;
  CAPTURE(to_string(mode));
  std::size_t total = 0;
  ColliderOptions serial_options, parallel_options;
  serial_options.mode = parallel_options.mode = mode;
  parallel_options.use_openmp = true;
  Collider serial(scene.asset, serial_options), parallel(scene.asset, parallel_options);
  std::vector<Contact> a(1 << 16), b(1 << 16);
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    REQUIRE(serial.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    REQUIRE(parallel.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    CHECK(any_ok(serial) == any_ok(parallel));
    REQUIRE(serial.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    REQUIRE(parallel.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    const EarliestContact ea = earliest_ok(serial), eb = earliest_ok(parallel);
    REQUIRE(ea.found == eb.found);
    if (ea.found) {
      CHECK(ea.contact.nodes == eb.contact.nodes);
      CHECK(ea.contact.toi == eb.contact.toi);
    }
    CHECK(contacts_ok(serial, nullptr, 0).found == contacts_ok(parallel, nullptr, 0).found);
    CHECK(serial.stats().traversal_threads == 1);
    REQUIRE(parallel.stats().traversal_threads > 1);  // parallel against serial, not serial twice
    CHECK(serial.stats().triangles_positive == parallel.stats().triangles_positive);
    CHECK(serial.stats().triangles_uncertain == parallel.stats().triangles_uncertain);
    CHECK(serial.stats().feature_tests == parallel.stats().feature_tests);
    CHECK(serial.stats().triangle_pairs == parallel.stats().triangle_pairs);
    const ContactsResult ra = contacts_ok(serial, a.data(), a.size());
    const ContactsResult rb = contacts_ok(parallel, b.data(), b.size());
    REQUIRE(ra.found == rb.found);
    total += ra.found;
    for (std::size_t i = 0; i < ra.written; ++i) {
      CHECK(a[i].nodes == b[i].nodes);
      CHECK(a[i].toi == b[i].toi);
    }
  }
  CHECK(total > 0);
}

TEST_CASE("Parallel brute force equals serial brute force", "[collider][openmp]") {
  const Scene scene = make_axial_scene(sphere(1.0, 24, 13), {0.0}, {-0.4, 0.4});
  const auto frames = make_frames(scene, 6, squash);
  ColliderOptions serial_options, parallel_options;
  serial_options.mode = parallel_options.mode = ColliderMode::kBrute;
  parallel_options.use_openmp = true;
  Collider serial(scene.asset, serial_options), parallel(scene.asset, parallel_options);
  std::size_t total = 0;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    REQUIRE(serial.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    REQUIRE(parallel.step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    const EarliestContact ea = earliest_ok(serial), eb = earliest_ok(parallel);
    REQUIRE(ea.found == eb.found);
    if (ea.found) CHECK(ea.contact.nodes == eb.contact.nodes);
    CHECK(contacts_ok(serial, nullptr, 0).found == contacts_ok(parallel, nullptr, 0).found);
    CHECK(serial.stats().traversal_threads == 1);
    REQUIRE(parallel.stats().traversal_threads > 1);  // parallel against serial, not serial twice
    CHECK(serial.stats().feature_tests == parallel.stats().feature_tests);
    total += contacts_ok(serial, nullptr, 0).found;
  }
  CHECK(total > 0);
}
