// `include_still_pairs` (ColliderOptions, SceneOptions) against the brute-force oracle with
// still pairs included: a still floor made of two overlapping grids in one plane (their
// coplanar triangles touch for the whole step: the still pairs the default rule skips), a
// still box resting on it and a moving box landing on it. With the option every mode reports
// exactly the oracle's contacts, still ones included; without it exactly the default oracle's
// (which has fewer: the scene is built so that the option matters).

#include <catch2/catch.hpp>
#include <memory>
#include <vector>

#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/scene.hpp"
#include "tetseg/testing/scene_oracle.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using tetseg::BodyShape;
using tetseg::ColliderMode;
using tetseg::ColliderStatus;
using tetseg::Contact;
using tetseg::ContactsResult;
using tetseg::test::P3;
using tetseg::test::Surface;

namespace {

/// Two n x n grids of [0, 1]^2 at z = 0, the second shifted by a third of a cell in x and y:
/// still triangles of one body crossing each other in one plane.
Surface overlapping_floor(int n) {
  Surface s;
  for (int layer = 0; layer < 2; ++layer) {
    const double shift = layer == 0 ? 0.0 : 1.0 / (3.0 * n);
    const auto base = static_cast<std::uint32_t>(s.verts.size());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        s.verts.push_back({double(i) / n + shift, double(j) / n + shift, 0});
    auto id = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        s.tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        s.tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
  }
  return s;
}

/// Appends surface b to a (node ids shifted).
void append(Surface& a, const Surface& b) {
  const auto base = static_cast<std::uint32_t>(a.verts.size());
  a.verts.insert(a.verts.end(), b.verts.begin(), b.verts.end());
  for (const auto& t : b.tris) a.tris.push_back({t[0] + base, t[1] + base, t[2] + base});
}

std::vector<double> flat(const std::vector<P3>& v) {
  std::vector<double> out;
  for (const P3& p : v) out.insert(out.end(), p.begin(), p.end());
  return out;
}

std::shared_ptr<const BodyShape> shape_of(const Surface& s) {
  std::vector<std::uint32_t> ids;
  for (const auto& t : s.tris) ids.insert(ids.end(), t.begin(), t.end());
  auto shape = BodyShape::from_triangles(ids.data(), s.tris.size(),
                                         static_cast<std::uint32_t>(s.verts.size()));
  REQUIRE(shape);
  return shape;
}

bool same_contact(const Contact& a, const Contact& b) {
  return a.kind == b.kind && a.bodies == b.bodies && a.nodes == b.nodes &&
         a.triangle == b.triangle && a.toi == b.toi && a.at_start == b.at_start;
}

void require_same(const std::vector<Contact>& got, const std::vector<Contact>& want) {
  REQUIRE(got.size() == want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    INFO("contact " << i);
    REQUIRE(same_contact(got[i], want[i]));
  }
}

/// The moving box: from 0.3 above the floor down to resting on it (its bottom at z = 0).
Surface landing_box() {
  return tetseg::test::box_surface({0.41, 0.43, 0.3}, {0.62, 0.66, 0.5}, 2);
}

}  // namespace

TEST_CASE("include_still_pairs: a Collider reports the still floor's contacts as brute force") {
  // One surface-only body: the overlapping floor and the box landing on it.
  Surface body = overlapping_floor(6);
  const auto floor_nodes = body.verts.size();
  append(body, landing_box());
  const std::vector<double> x0 = flat(body.verts);
  std::vector<double> x1 = x0;
  for (std::size_t n = floor_nodes; n < body.verts.size(); ++n) x1[3 * n + 2] -= 0.3;
  const tetseg::test::OracleBody oracle_body{body.tris.data(), body.tris.size(), x0.data(),
                                             x1.data(), true};
  const std::vector<Contact> with_still = tetseg::test::scene_brute_contacts({oracle_body}, true);
  const std::vector<Contact> without = tetseg::test::scene_brute_contacts({oracle_body});
  // The still floor touches itself: the option must matter here.
  REQUIRE(with_still.size() > without.size() + 20);
  REQUIRE(!without.empty());  // the landing box touches the floor at t = 1

  const auto shape = shape_of(body);
  for (ColliderMode mode : {ColliderMode::kBvh, ColliderMode::kCone, ColliderMode::kBrute}) {
    for (bool include : {false, true}) {
      INFO("mode " << tetseg::to_string(mode) << ", include_still_pairs " << include);
      tetseg::ColliderOptions options;
      options.mode = mode;
      options.include_still_pairs = include;
      tetseg::Collider collider(shape, options);
      REQUIRE(collider.step(x0.data(), x1.data(), x0.size()) == ColliderStatus::kOk);
      std::vector<Contact> buffer(with_still.size() + 16);
      ContactsResult r;
      REQUIRE(collider.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOk);
      REQUIRE(!r.truncated());
      buffer.resize(r.written);
      require_same(buffer, include ? with_still : without);
      tetseg::EarliestContact earliest;
      REQUIRE(collider.earliest_toi(earliest) == ColliderStatus::kOk);
      REQUIRE(earliest.found);
      REQUIRE(same_contact(earliest.contact, (include ? with_still : without).front()));
    }
  }

  SECTION("a step where nothing moves still lists the still contacts") {
    tetseg::ColliderOptions options;
    options.mode = ColliderMode::kBvh;
    options.include_still_pairs = true;
    tetseg::Collider collider(shape, options);
    REQUIRE(collider.step(x1.data(), x1.data(), x1.size()) == ColliderStatus::kOk);
    REQUIRE(!collider.stats().nothing_moved);
    const tetseg::test::OracleBody at_rest{body.tris.data(), body.tris.size(), x1.data(), x1.data(),
                                           true};
    const std::vector<Contact> want = tetseg::test::scene_brute_contacts({at_rest}, true);
    REQUIRE(!want.empty());
    std::vector<Contact> buffer(want.size() + 16);
    ContactsResult r;
    REQUIRE(collider.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOk);
    buffer.resize(r.written);
    require_same(buffer, want);
  }
}

TEST_CASE("include_still_pairs: a Scene with a still floor and a still box reports brute force") {
  // Body 0: the still overlapping floor; body 1: a still box resting on it; body 2: the box
  // landing on the floor beside it.
  const Surface floor = overlapping_floor(5);
  const Surface resting = tetseg::test::box_surface({0.1, 0.1, 0.0}, {0.3, 0.3, 0.2}, 2);
  const Surface landing = landing_box();
  const std::vector<double> floor_x = flat(floor.verts), resting_x = flat(resting.verts);
  const std::vector<double> landing_x0 = flat(landing.verts);
  std::vector<double> landing_x1 = landing_x0;
  for (std::size_t n = 0; n < landing.verts.size(); ++n) landing_x1[3 * n + 2] -= 0.3;
  const std::vector<tetseg::test::OracleBody> oracle = {
      {floor.tris.data(), floor.tris.size(), floor_x.data(), floor_x.data(), true},
      {resting.tris.data(), resting.tris.size(), resting_x.data(), resting_x.data(), true},
      {landing.tris.data(), landing.tris.size(), landing_x0.data(), landing_x1.data(), true}};
  const std::vector<Contact> with_still = tetseg::test::scene_brute_contacts(oracle, true);
  const std::vector<Contact> without = tetseg::test::scene_brute_contacts(oracle);
  REQUIRE(with_still.size() > without.size() + 20);
  bool floor_resting = false;  // a still contact between two still bodies
  for (const Contact& c : with_still)
    floor_resting = floor_resting || c.bodies == std::array<std::uint32_t, 2>{0, 1};
  REQUIRE(floor_resting);

  for (bool include : {false, true}) {
    INFO("include_still_pairs " << include);
    tetseg::SceneOptions options;
    options.include_still_pairs = include;
    tetseg::Scene scene(options);
    tetseg::BodyOptions still_body;
    still_body.still = true;
    still_body.mode = ColliderMode::kBvh;
    tetseg::BodyOptions moving_body;
    moving_body.mode = ColliderMode::kBvh;
    REQUIRE(scene.add_body(shape_of(floor), still_body) == ColliderStatus::kOk);
    REQUIRE(scene.add_body(shape_of(resting), still_body) == ColliderStatus::kOk);
    REQUIRE(scene.add_body(shape_of(landing), moving_body) == ColliderStatus::kOk);
    REQUIRE(scene.set_positions(0, floor_x.data(), nullptr, floor_x.size()) == ColliderStatus::kOk);
    REQUIRE(scene.set_positions(1, resting_x.data(), nullptr, resting_x.size()) ==
            ColliderStatus::kOk);
    REQUIRE(scene.set_positions(2, landing_x0.data(), landing_x1.data(), landing_x0.size()) ==
            ColliderStatus::kOk);
    REQUIRE(scene.step() == ColliderStatus::kOk);
    std::vector<Contact> buffer(with_still.size() + 16);
    ContactsResult r;
    REQUIRE(scene.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOk);
    REQUIRE(!r.truncated());
    buffer.resize(r.written);
    require_same(buffer, include ? with_still : without);
  }
}
