// Contacts into a caller's buffer on OpenMP threads (use_openmp, threads = 2) against the
// serial path, in every mode: the same contacts in the same order, the same earliest contact
// and counts; a truncated buffer holds the smallest contacts either way. The parallel path is
// proven to run (ColliderStats::traversal_threads == 2), so this never compares serial with
// serial. Built only with OpenMP (without it there is no parallel path to test).

#if defined(TETSEG_TEST_OPENMP)

#include <catch2/catch.hpp>
#include <memory>
#include <vector>

#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/scene.hpp"
#include "tetseg/testing/allocation_probe.hpp"
#include "tetseg/testing/scene_oracle.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using tetseg::ColliderMode;
using tetseg::ColliderStatus;
using tetseg::Contact;
using tetseg::ContactsResult;
using tetseg::test::P3;

namespace {

bool same_contact(const Contact& a, const Contact& b) {
  return a.kind == b.kind && a.bodies == b.bodies && a.nodes == b.nodes &&
         a.triangle == b.triangle && a.toi == b.toi && a.at_start == b.at_start;
}

template <typename Query>
std::vector<Contact> contacts_of(Query& q, std::size_t capacity, ContactsResult& r) {
  std::vector<Contact> buffer(capacity);
  REQUIRE(q.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOk);
  buffer.resize(r.written);
  return buffer;
}

void require_same(const std::vector<Contact>& a, const std::vector<Contact>& b) {
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    INFO("contact " << i);
    REQUIRE(same_contact(a[i], b[i]));
  }
}

/// A dumbbell bent past contact in one step (its bells pass through each other): hundreds
/// of contacts, in three clusters along the axis.
struct BentDumbbell {
  explicit BentDumbbell(int segments = 14, int rings = 20)
      : surface(tetseg::test::dumbbell(segments, rings)) {}
  tetseg::test::Surface surface;
  tetseg::test::Scene scene = tetseg::test::make_axial_scene(surface, {-0.8, 0.8}, {-1.6, 0, 1.6});
  std::vector<std::vector<double>> frames = tetseg::test::make_frames(
      scene, 2,
      [](const P3& p, double t) { return tetseg::test::bend_about_x(p, t, 3.4, -0.5, 0.5, 0.0); });
};

}  // namespace

TEST_CASE("Collider contacts into a buffer on two threads equal the serial ones, order included",
          "[collider][openmp]") {
  const BentDumbbell db;
  const double* x0 = db.frames[0].data();
  const double* x1 = db.frames[1].data();
  for (ColliderMode mode : {ColliderMode::kRvbc, ColliderMode::kBvh, ColliderMode::kCone,
                            ColliderMode::kBrute, ColliderMode::kFeatures}) {
    INFO("mode " << tetseg::to_string(mode));
    tetseg::ColliderOptions serial_options;
    serial_options.mode = mode;
    tetseg::ColliderOptions parallel_options = serial_options;
    parallel_options.use_openmp = true;
    parallel_options.threads = 2;
    tetseg::Collider serial(db.scene.asset, serial_options);
    tetseg::Collider parallel(db.scene.asset, parallel_options);
    for (tetseg::Collider* c : {&serial, &parallel})
      REQUIRE(c->step(x0, x1) == ColliderStatus::kOk);

    ContactsResult rs, rp;
    const std::vector<Contact> all_serial = contacts_of(serial, 100000, rs);
    const std::vector<Contact> all_parallel = contacts_of(parallel, 100000, rp);
    REQUIRE(serial.stats().traversal_threads == 1);
    REQUIRE(parallel.stats().traversal_threads == 2);  // the parallel path ran
    REQUIRE(rs.found == rp.found);
    REQUIRE(!rs.truncated());
    REQUIRE(rs.found > 100);  // a contact-rich step
    require_same(all_serial, all_parallel);
    const tetseg::ColliderStats& ss = serial.stats();
    const tetseg::ColliderStats& ps = parallel.stats();
    CHECK(ss.node_pairs_visited == ps.node_pairs_visited);
    CHECK(ss.triangle_pairs == ps.triangle_pairs);
    CHECK(ss.feature_pairs == ps.feature_pairs);
    CHECK(ss.feature_tests == ps.feature_tests);
    CHECK(ss.contacts == ps.contacts);

    // A truncated buffer: the smallest contacts in contact_less order, on both paths.
    const std::size_t capacity = rs.found / 3;
    const std::vector<Contact> part_serial = contacts_of(serial, capacity, rs);
    const std::vector<Contact> part_parallel = contacts_of(parallel, capacity, rp);
    REQUIRE(rs.truncated());
    REQUIRE(rp.truncated());
    REQUIRE(parallel.stats().traversal_threads == 2);
    require_same(part_serial, std::vector<Contact>(all_serial.begin(),
                                                   all_serial.begin() + std::ptrdiff_t(capacity)));
    require_same(part_parallel, part_serial);

    tetseg::EarliestContact es, ep;
    REQUIRE(serial.earliest_toi(es) == ColliderStatus::kOk);
    REQUIRE(parallel.earliest_toi(ep) == ColliderStatus::kOk);
    REQUIRE(es.found);
    REQUIRE(ep.found);
    REQUIRE(same_contact(es.contact, all_serial.front()));
    REQUIRE(same_contact(ep.contact, es.contact));
  }
}

TEST_CASE("A step on two threads classifies every triangle as the serial step does",
          "[collider][openmp]") {
  // At least 1,024 triangles: the classification runs on the workers from there (collider.cpp,
  // kParallelClassifyItems).
  const BentDumbbell db(40, 24);
  REQUIRE(db.surface.tris.size() >= 1024);
  tetseg::ColliderOptions serial_options;
  tetseg::ColliderOptions parallel_options = serial_options;
  parallel_options.use_openmp = true;
  parallel_options.threads = 2;
  tetseg::Collider serial(db.scene.asset, serial_options);
  tetseg::Collider parallel(db.scene.asset, parallel_options);
  for (tetseg::Collider* c : {&serial, &parallel})
    REQUIRE(c->step(db.frames[0].data(), db.frames[1].data()) == ColliderStatus::kOk);
  const tetseg::ColliderStats& ss = serial.stats();
  const tetseg::ColliderStats& ps = parallel.stats();
  REQUIRE(ss.step_threads == 1);
  REQUIRE(ps.step_threads == 2);  // the parallel classification ran
  // A bend past contact leaves triangles of every class, so a triangle left unclassified or
  // classified against the wrong positions shows.
  REQUIRE(ss.triangles_positive > 0);
  REQUIRE(ss.triangles_negative + ss.triangles_uncertain > 0);
  std::size_t differ = 0;
  for (std::size_t t = 0; t < db.surface.tris.size(); ++t)
    differ += serial.triangle_class(t) != parallel.triangle_class(t) ? 1 : 0;
  CHECK(differ == 0);
  CHECK(ss.nodes_moved == ps.nodes_moved);
  CHECK(ss.triangles_moving == ps.triangles_moving);
  CHECK(ss.triangles_positive == ps.triangles_positive);
  CHECK(ss.triangles_negative == ps.triangles_negative);
  CHECK(ss.triangles_uncertain == ps.triangles_uncertain);
  // And the contacts, in the same order.
  ContactsResult rs, rp;
  const std::vector<Contact> all_serial = contacts_of(serial, 100000, rs);
  const std::vector<Contact> all_parallel = contacts_of(parallel, 100000, rp);
  REQUIRE(parallel.stats().traversal_threads == 2);
  REQUIRE(rs.found > 100);
  require_same(all_serial, all_parallel);
}

TEST_CASE("The bvh mode on two threads reports brute force's contacts", "[collider][openmp]") {
  const BentDumbbell db;
  const auto& s = db.scene;
  const tetseg::test::OracleBody body{db.surface.tris.data(), db.surface.tris.size(),
                                      db.frames[0].data(), db.frames[1].data(), true};
  const std::vector<Contact> truth = tetseg::test::scene_brute_contacts({body});
  tetseg::ColliderOptions options;
  options.mode = ColliderMode::kBvh;
  options.use_openmp = true;
  options.threads = 2;
  tetseg::Collider parallel(s.asset, options);
  REQUIRE(parallel.step(db.frames[0].data(), db.frames[1].data()) == ColliderStatus::kOk);
  ContactsResult r;
  const std::vector<Contact> got = contacts_of(parallel, truth.size() + 16, r);
  REQUIRE(parallel.stats().traversal_threads == 2);
  REQUIRE(truth.size() > 100);
  require_same(got, truth);
}

TEST_CASE("Steps and queries on two threads allocate nothing, contact buffer included",
          "[collider][openmp]") {
  const BentDumbbell db(40, 24);  // the classification on the workers too
  for (ColliderMode mode : {ColliderMode::kRvbc, ColliderMode::kBvh, ColliderMode::kCone}) {
    INFO("mode " << tetseg::to_string(mode));
    tetseg::ColliderOptions options;
    options.mode = mode;
    options.use_openmp = true;
    options.threads = 2;
    tetseg::Collider collider(db.scene.asset, options);
    std::vector<Contact> buffer(100000);
    for (int round = 0; round < 2; ++round) {  // the first step as well as later ones
      tetseg::test::AllocationProbe probe;
      REQUIRE(collider.step(db.frames[0].data(), db.frames[1].data()) == ColliderStatus::kOk);
      ContactsResult r;
      REQUIRE(collider.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOk);
      REQUIRE(collider.stats().traversal_threads == 2);
      if (mode == ColliderMode::kRvbc) REQUIRE(collider.stats().step_threads == 2);
      REQUIRE(r.found > 100);
      tetseg::EarliestContact e;
      REQUIRE(collider.earliest_toi(e) == ColliderStatus::kOk);
      REQUIRE(probe.count() == 0);
    }
  }
}

TEST_CASE("Scene contacts into a buffer on two threads equal the serial ones", "[scene][openmp]") {
  // The bent dumbbell (rvbc) and a still box its upper bell passes through, plus a second,
  // moving copy of the box (surface-only bodies): self contacts and pairs of bodies.
  const BentDumbbell db;
  auto dumbbell_shape = tetseg::BodyShape::from_asset(db.scene.asset);
  REQUIRE(dumbbell_shape);
  const tetseg::test::Surface box =
      tetseg::test::box_surface({-0.5, -0.5, 1.0}, {0.5, 0.5, 1.4}, 3);
  std::vector<std::uint32_t> ids;
  for (const auto& t : box.tris) ids.insert(ids.end(), t.begin(), t.end());
  auto box_shape = tetseg::BodyShape::from_triangles(ids.data(), box.tris.size(),
                                                     static_cast<std::uint32_t>(box.verts.size()));
  REQUIRE(box_shape);
  std::vector<double> box0, box1;
  for (const P3& p : box.verts) {
    box0.insert(box0.end(), p.begin(), p.end());
    box1.insert(box1.end(), {p[0] + 0.1, p[1], p[2] + 0.5});
  }
  auto make = [&](bool threads) {
    tetseg::SceneOptions options;
    options.use_openmp = threads;
    options.threads = 2;
    auto scene = std::make_unique<tetseg::Scene>(options);
    tetseg::BodyOptions still;
    still.still = true;
    REQUIRE(scene->add_body(dumbbell_shape, {}) == ColliderStatus::kOk);
    REQUIRE(scene->add_body(box_shape, still) == ColliderStatus::kOk);
    REQUIRE(scene->add_body(box_shape, {}) == ColliderStatus::kOk);
    REQUIRE(scene->set_positions(0, db.frames[0].data(), db.frames[1].data(),
                                 db.frames[0].size()) == ColliderStatus::kOk);
    REQUIRE(scene->set_positions(1, box0.data(), nullptr, box0.size()) == ColliderStatus::kOk);
    REQUIRE(scene->set_positions(2, box0.data(), box1.data(), box0.size()) == ColliderStatus::kOk);
    REQUIRE(scene->step() == ColliderStatus::kOk);
    return scene;
  };
  auto serial = make(false);
  auto parallel = make(true);
  ContactsResult rs, rp;
  const std::vector<Contact> all_serial = contacts_of(*serial, 100000, rs);
  const std::vector<Contact> all_parallel = contacts_of(*parallel, 100000, rp);
  REQUIRE(parallel->body_stats(0).traversal_threads == 2);
  REQUIRE(serial->body_stats(0).traversal_threads == 1);
  REQUIRE(rs.found > 100);
  bool across = false;
  for (const Contact& c : all_serial) across = across || c.bodies[0] != c.bodies[1];
  REQUIRE(across);
  require_same(all_serial, all_parallel);
  const std::size_t capacity = rs.found / 2;
  const std::vector<Contact> part_serial = contacts_of(*serial, capacity, rs);
  const std::vector<Contact> part_parallel = contacts_of(*parallel, capacity, rp);
  REQUIRE(rp.truncated());
  require_same(part_serial, std::vector<Contact>(all_serial.begin(),
                                                 all_serial.begin() + std::ptrdiff_t(capacity)));
  require_same(part_parallel, part_serial);
}

#endif  // TETSEG_TEST_OPENMP
