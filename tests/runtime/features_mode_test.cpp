// ColliderMode::kFeatures (per-feature BVHs, collider_features.cpp) against independent truth:
// the brute-force oracle over all feature pairs (scene_oracle.hpp: the runtime's elementary
// tests on every pair, no broad phase) and the exact rational oracle (exact_scene_oracle.hpp),
// on random triangle soups (separate triangles and a connected strip, some nodes still) and
// on a libcgal-demo mesh deformed over steps until it touches itself. Every contact the
// oracle finds is reported, each once, at the oracle's time, nothing else; with
// `include_still_pairs` the still pairs too; the brute mode's contacts are the same list. The
// trees' float bounds (feature_bounds.hpp) are the nearest floats outwards, and contacts
// exactly at box and slab ends survive them at offsets up to 1e6 and scales 1e-4 .. 1e4.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "../../runtime/src/feature_bounds.hpp"

#include "runtime/support/compare.hpp"
#include "runtime/support/motions.hpp"
#include "runtime/support/off.hpp"
#include "tetseg/runtime/body_shape.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/scene.hpp"

using namespace tetseg;
using namespace tetseg::test;

namespace {

/// A random soup: `loose` separate small triangles and a strip of `strip` triangles sharing
/// nodes, in the unit cube, each node moving by up to `motion` per axis; nodes with an index
/// divisible by `still_every` (0: none) do not move, and then two still triangles overlap in
/// one plane (still pairs touching for the whole step).
struct Soup {
  std::vector<format::Triangle> tris;
  std::vector<double> x0, x1;
};

Soup random_soup(unsigned seed, int loose, int strip, double motion, int still_every) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Soup s;
  auto node = [&](double x, double y, double z, bool force_still = false) {
    const auto id = static_cast<std::uint32_t>(s.x0.size() / 3);
    const bool still =
        force_still || (still_every > 0 && id % static_cast<std::uint32_t>(still_every) == 0);
    for (double c : {x, y, z}) {
      s.x0.push_back(c);
      s.x1.push_back(still ? c : c + motion * (u(rng) - 0.5));
    }
    return id;
  };
  for (int i = 0; i < loose; ++i) {
    const double cx = u(rng), cy = u(rng), cz = u(rng);
    std::uint32_t v[3];
    for (auto& id : v) id = node(cx + 0.15 * u(rng), cy + 0.15 * u(rng), cz + 0.15 * u(rng));
    s.tris.push_back({v[0], v[1], v[2]});
  }
  // A zigzag strip along x with a random wave in z: neighbours share edges and nodes.
  std::uint32_t a = node(0, 0.5, 0.5), b = node(0, 0.6, 0.5 + 0.05 * u(rng));
  for (int i = 0; i < strip; ++i) {
    const double x = 0.02 * (i + 1);
    const std::uint32_t c = node(x, i % 2 ? 0.6 : 0.5, 0.5 + 0.1 * (u(rng) - 0.5));
    s.tris.push_back({a, b, c});
    a = b;
    b = c;
  }
  if (still_every > 0) {
    for (double d : {0.0, 0.1}) {
      const std::uint32_t p = node(0.1 + d, 0.1 + d, 0.2, true);
      const std::uint32_t q = node(0.4 + d, 0.1 + d, 0.2, true);
      const std::uint32_t r = node(0.1 + d, 0.4 + d, 0.2, true);
      s.tris.push_back({p, q, r});
    }
  }
  return s;
}

std::shared_ptr<const BodyShape> shape_of(const std::vector<format::Triangle>& tris,
                                          std::size_t nodes) {
  std::vector<std::uint32_t> ids;
  for (const auto& t : tris) ids.insert(ids.end(), t.begin(), t.end());
  auto shape =
      BodyShape::from_triangles(ids.data(), tris.size(), static_cast<std::uint32_t>(nodes));
  REQUIRE(shape);
  return shape;
}

std::vector<Contact> contacts_of(const std::shared_ptr<const BodyShape>& shape,
                                 ColliderOptions options, const double* x0, const double* x1) {
  Collider collider(shape, options);
  REQUIRE(collider.status() == ColliderStatus::kOk);
  std::vector<Contact> found = answer(collider, x0, x1).contacts;
  std::sort(found.begin(), found.end(), contact_less);
  return found;
}

/// Same features, times and start flags, in the same (contact_less) order.
void require_same_list(const std::vector<Contact>& got, const std::vector<Contact>& want) {
  REQUIRE(got.size() == want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    CAPTURE(i, describe(got[i]), describe(want[i]));
    REQUIRE(same_feature(got[i], want[i]));
    REQUIRE(got[i].toi == want[i].toi);
    REQUIRE(got[i].at_start == want[i].at_start);
  }
}

}  // namespace

TEST_CASE("Features mode: random soups report exactly the brute-force oracle's contacts",
          "[collider][features][oracle]") {
  int with_contacts = 0, still_only = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    const Soup s = random_soup(seed, 60, 40, 0.3, seed % 3 == 0 ? 0 : 4);
    const auto shape = shape_of(s.tris, s.x0.size() / 3);
    const OracleBody body{s.tris.data(), s.tris.size(), s.x0.data(), s.x1.data(), true};
    // Default still rule: the oracle's list exactly, and every exact contact (step_truth
    // requires the oracle to hold each at a time no later than the exact one).
    ColliderOptions options;
    options.mode = ColliderMode::kFeatures;
    const std::vector<Contact> features = contacts_of(shape, options, s.x0.data(), s.x1.data());
    require_same_list(features, scene_brute_contacts({body}));
    const StepTruth truth = step_truth(body);
    StepAnswer a;
    a.contacts = features;
    a.any = !features.empty();
    a.earliest.found = a.any;
    if (a.any) a.earliest.contact = features.front();
    require_matches_oracle(a, truth, Expect::kAllContacts);
    with_contacts += truth.required.empty() ? 0 : 1;
    // The brute mode lists the same contacts.
    ColliderOptions brute = options;
    brute.mode = ColliderMode::kBrute;
    require_same_list(features, contacts_of(shape, brute, s.x0.data(), s.x1.data()));
    // Still pairs included: the oracle with still pairs, which has more when nodes are still.
    options.include_still_pairs = true;
    const std::vector<Contact> with_still = contacts_of(shape, options, s.x0.data(), s.x1.data());
    const std::vector<Contact> oracle_still = scene_brute_contacts({body}, true);
    require_same_list(with_still, oracle_still);
    still_only += with_still.size() > features.size() ? 1 : 0;
  }
  CHECK(with_contacts >= 10);  // the soups do collide: the comparison is not vacuous
  CHECK(still_only >= 1);      // and some contacts are between still nodes only
}

TEST_CASE("Features mode: float bounds are the nearest floats outwards",
          "[collider][features][rounding]") {
  // float_down(d) is the largest float <= d and float_up(d) the smallest >= d, at every scale
  // and offset (and beyond the float range, and for denormals). The trees' lanes hold them.
  const float kMax = std::numeric_limits<float>::max();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> values = {0.0,    -0.0,   1e-310, -1e-310,   1e-45,    -1e-45, 1.4e-45,
                                3e-39,  -3e-39, kMax,   -kMax,     1e39,     -1e39,  1e300,
                                -1e300, 0.1,    -0.1,   1e6 + 0.1, 1.0 / 3.0};
  for (double offset : {0.0, 1e6, -1e6, 1e30})
    for (double scale : {1e-4, 1e-2, 1.0, 1e2, 1e4})
      for (int i = 0; i < 2000; ++i) values.push_back(offset + scale * u(rng));
  int inexact = 0;
  for (const double d : values) {
    CAPTURE(d);
    const float lo = float_down(d), hi = float_up(d);
    REQUIRE(static_cast<double>(lo) <= d);
    REQUIRE(static_cast<double>(hi) >= d);
    if (d >= kMax) {
      CHECK(lo == kMax);
    } else {
      REQUIRE(static_cast<double>(std::nextafter(lo, INFINITY)) > d);  // no float between
    }
    if (d <= -kMax) {
      CHECK(hi == -kMax);
    } else {
      REQUIRE(static_cast<double>(std::nextafter(hi, -INFINITY)) < d);
    }
    inexact += lo != hi ? 1 : 0;
  }
  CHECK(inexact > 30000);  // most values are not floats: the rounding is exercised
}

TEST_CASE("Features mode: contacts exactly at the ends of boxes and slabs are found",
          "[collider][features][oracle][rounding]") {
  // A vertex reaching a face's corner a at t = 1 along a direction s, the face stretching away
  // from a along s: the vertex's box and its slab along s end exactly where the face's begin,
  // so bounds that are not closed, or narrower than the exact ones (a lo rounded up, a hi
  // rounded down), lose the contact. Every slab direction (the four diagonals and the six
  // edge diagonals), at large offsets and at scales 1e-4 .. 1e4, with coordinates that are not
  // floats; exactly the brute mode's contacts, and the exact oracle's at unit scale.
  const double directions[10][3] = {{1, 1, 1},  {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, 0},
                                    {1, -1, 0}, {1, 0, 1},  {1, 0, -1}, {0, 1, 1},  {0, 1, -1}};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::vector<format::Triangle> tris = {{0, 1, 2}, {3, 4, 5}};
  const auto shape = shape_of(tris, 6);
  int found = 0;
  for (const auto& s : directions) {
    for (double scale : {1e-4, 1e-2, 1.0, 1e2, 1e4}) {
      for (double offset : {0.0, 1e6, -3e5}) {
        CAPTURE(s[0], s[1], s[2], scale, offset);
        double a[3];
        for (double& c : a) c = offset + scale * (0.3 + 0.1 * u(rng));
        // The face spans from a along two axes where s is not zero.
        int axis[2] = {0, 1};
        if (s[0] == 0) axis[0] = 2;
        if (s[1] == 0) axis[1] = 2;
        std::vector<double> x0(18), x1(18);
        for (auto* x : {&x0, &x1}) {
          for (int k = 0; k < 3; ++k) {
            (*x)[k] = (*x)[3 + k] = (*x)[6 + k] = a[k];
            (*x)[12 + k] = a[k] + 5 * scale;  // the vertex's triangle, far off
            (*x)[15 + k] = a[k] + (k == 1 ? 6 : 5) * scale;
          }
          (*x)[3 + axis[0]] += s[axis[0]] * 0.75 * scale;
          (*x)[6 + axis[1]] += s[axis[1]] * 0.5 * scale;
        }
        for (int k = 0; k < 3; ++k) {
          x0[9 + k] = a[k] - 0.25 * scale * s[k];
          x1[9 + k] = a[k];
        }
        ColliderOptions options;
        options.mode = ColliderMode::kFeatures;
        const std::vector<Contact> features = contacts_of(shape, options, x0.data(), x1.data());
        ColliderOptions brute = options;
        brute.mode = ColliderMode::kBrute;
        const std::vector<Contact> want = contacts_of(shape, brute, x0.data(), x1.data());
        REQUIRE_FALSE(want.empty());
        require_same_list(features, want);
        if (scale == 1.0 && offset == 0.0) {
          const OracleBody body{tris.data(), tris.size(), x0.data(), x1.data(), true};
          Collider collider(shape, options);
          require_matches_oracle(answer(collider, x0.data(), x1.data()), step_truth(body),
                                 Expect::kAllContacts);
        }
        ++found;
      }
    }
  }
  CHECK(found == 150);
}

TEST_CASE("Features mode: soups at large offsets and scales report the brute mode's contacts",
          "[collider][features][rounding]") {
  // The float lanes at every magnitude (1e6 offsets leave floats a step of 0.06 over a soup
  // of size 1e-4), with and without a minimum separation (the margin added to every hi), and
  // soups of one to nine triangles (partial leaves, a root that is a leaf).
  int with_contacts = 0;
  for (double scale : {1e-4, 1e-2, 1.0, 1e2, 1e4}) {
    for (double offset : {0.0, 1e6}) {
      for (int size : {1, 2, 3, 5, 9, 60}) {
        CAPTURE(scale, offset, size);
        Soup s = random_soup(static_cast<unsigned>(size * 31 + scale * 7), size, size / 2 + 1, 0.4,
                             size % 2 ? 0 : 3);
        for (auto* x : {&s.x0, &s.x1})
          for (double& c : *x) c = offset + scale * c;
        const auto shape = shape_of(s.tris, s.x0.size() / 3);
        for (double separation : {0.0, 0.01}) {
          CAPTURE(separation);
          ColliderOptions options;
          options.mode = ColliderMode::kFeatures;
          options.ccd.min_separation = separation * scale;
          const std::vector<Contact> features =
              contacts_of(shape, options, s.x0.data(), s.x1.data());
          ColliderOptions brute = options;
          brute.mode = ColliderMode::kBrute;
          require_same_list(features, contacts_of(shape, brute, s.x0.data(), s.x1.data()));
          with_contacts += features.empty() ? 0 : 1;
        }
      }
    }
  }
  CHECK(with_contacts >= 60);  // the comparison is not vacuous
}

TEST_CASE("Features mode: a minimum separation reports what the brute mode reports",
          "[collider][features]") {
  for (unsigned seed = 20; seed <= 24; ++seed) {
    CAPTURE(seed);
    const Soup s = random_soup(seed, 50, 30, 0.2, 5);
    const auto shape = shape_of(s.tris, s.x0.size() / 3);
    ColliderOptions options;
    options.mode = ColliderMode::kFeatures;
    options.ccd.min_separation = 0.01;
    ColliderOptions brute = options;
    brute.mode = ColliderMode::kBrute;
    const std::vector<Contact> features = contacts_of(shape, options, s.x0.data(), s.x1.data());
    CHECK_FALSE(features.empty());
    require_same_list(features, contacts_of(shape, brute, s.x0.data(), s.x1.data()));
  }
}

TEST_CASE("Features mode: a deformed real mesh matches the exact oracle up to its first contact",
          "[collider][features][oracle][mesh]") {
  const std::string name = GENERATE(as<std::string>{}, "eight", "joint");
  CAPTURE(name);
  Surface mesh;
  if (!read_demo_surface(name, mesh)) return;
  const auto shape = shape_of(mesh.tris, mesh.verts.size());
  const double size = bounding_diagonal(mesh);
  const Waves waves(11, 0.2 * size, 6.0 / size);
  ColliderOptions options;
  options.mode = ColliderMode::kFeatures;
  Collider features(shape, options);
  options.mode = ColliderMode::kBvh;
  Collider bvh(shape, options);
  int steps = 0;
  bool touched = false;
  for (int f = 0; f < 10 && !touched; ++f) {
    CAPTURE(f);
    std::vector<double> x0, x1;
    motion_step(mesh, waves, f, 10, x0, x1);
    const OracleBody body{mesh.tris.data(), mesh.tris.size(), x0.data(), x1.data(), true};
    const StepTruth truth = step_truth(body);
    const StepAnswer a = answer(features, x0.data(), x1.data());
    require_matches_oracle(a, truth, Expect::kAllContacts);
    std::vector<Contact> got = a.contacts, want = answer(bvh, x0.data(), x1.data()).contacts;
    std::sort(got.begin(), got.end(), contact_less);
    std::sort(want.begin(), want.end(), contact_less);
    require_same_list(got, want);
    ++steps;
    touched = !truth.required.empty();
  }
  CHECK(touched);  // the deformation does make the surface touch itself
  CHECK(steps >= 2);
}

#if defined(TETSEG_TEST_OPENMP)
TEST_CASE("Features mode: two threads report the serial contacts and counts",
          "[collider][features][openmp]") {
  // Random soups (a few hundred triangles: tasks of both traversals) and a libcgal-demo mesh
  // deformed until it touches itself: the same contacts in the same order, the same earliest
  // contact and counts, and the parallel path did run.
  auto compare = [](const std::shared_ptr<const BodyShape>& shape, const double* x0,
                    const double* x1) {
    ColliderOptions serial_options;
    serial_options.mode = ColliderMode::kFeatures;
    ColliderOptions parallel_options = serial_options;
    parallel_options.use_openmp = true;
    parallel_options.threads = 2;
    Collider serial(shape, serial_options), parallel(shape, parallel_options);
    std::vector<Contact> s(1 << 16), p(1 << 16);
    for (Collider* c : {&serial, &parallel}) REQUIRE(c->step(x0, x1) == ColliderStatus::kOk);
    const ContactsResult rs = contacts_ok(serial, s.data(), s.size());
    const ContactsResult rp = contacts_ok(parallel, p.data(), p.size());
    REQUIRE(serial.stats().traversal_threads == 1);
    REQUIRE(parallel.stats().traversal_threads == 2);  // the parallel path ran
    REQUIRE_FALSE(rs.truncated());
    REQUIRE(rp.written == rs.written);
    for (std::size_t i = 0; i < rs.written; ++i) {
      CAPTURE(i);
      REQUIRE(same_feature(p[i], s[i]));
      REQUIRE(p[i].toi == s[i].toi);
      REQUIRE(p[i].at_start == s[i].at_start);
    }
    CHECK(parallel.stats().node_pairs_visited == serial.stats().node_pairs_visited);
    CHECK(parallel.stats().feature_pairs == serial.stats().feature_pairs);
    CHECK(parallel.stats().feature_tests == serial.stats().feature_tests);
    const EarliestContact es = earliest_ok(serial), ep = earliest_ok(parallel);
    REQUIRE(ep.found == es.found);
    if (es.found) REQUIRE(same_feature(ep.contact, es.contact));
    return rs.written;
  };
  std::size_t contacts = 0;
  for (unsigned seed = 40; seed < 46; ++seed) {
    CAPTURE(seed);
    const Soup s = random_soup(seed, 300, 200, 0.3, seed % 2 ? 0 : 5);
    contacts += compare(shape_of(s.tris, s.x0.size() / 3), s.x0.data(), s.x1.data());
  }
  CHECK(contacts > 100);  // not vacuous
  Surface mesh;
  if (!read_demo_surface("eight", mesh)) return;
  const auto shape = shape_of(mesh.tris, mesh.verts.size());
  const double size = bounding_diagonal(mesh);
  const Waves waves(11, 0.2 * size, 6.0 / size);
  std::size_t mesh_contacts = 0;
  for (int f = 0; f < 10; ++f) {
    CAPTURE(f);
    std::vector<double> x0, x1;
    motion_step(mesh, waves, f, 10, x0, x1);
    mesh_contacts += compare(shape, x0.data(), x1.data());
  }
  CHECK(mesh_contacts > 0);
}
#endif

TEST_CASE("Features mode: names, scenes and statuses", "[collider][features][api]") {
  ColliderMode parsed = ColliderMode::kRvbc;
  REQUIRE(parse_collider_mode("features", parsed));
  CHECK(parsed == ColliderMode::kFeatures);
  CHECK(std::string(to_string(ColliderMode::kFeatures)) == "features");
  // Not a scene body mode (like kBrute).
  const Soup s = random_soup(3, 60, 40, 0.3, 0);
  tetseg::Scene scene;
  BodyOptions body;
  body.mode = ColliderMode::kFeatures;
  CHECK(scene.add_body(shape_of(s.tris, s.x0.size() / 3), body) ==
        ColliderStatus::kInvalidArgument);
  // A traversal stack too small for the trees fails with kOverflow, not a partial answer.
  ColliderOptions options;
  options.mode = ColliderMode::kFeatures;
  options.traversal_stack = 2;
  Collider collider(shape_of(s.tris, s.x0.size() / 3), options);
  REQUIRE(collider.step(s.x0.data(), s.x1.data()) == ColliderStatus::kOk);
  std::vector<Contact> buffer(64);
  ContactsResult r;
  CHECK(collider.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOverflow);
  CHECK(r.written == 0);
}
