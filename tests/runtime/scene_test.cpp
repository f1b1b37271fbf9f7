// tetseg::Scene against an independent brute-force oracle over all bodies: every feature pair
// with four distinct nodes (vertex against triangle, edge against edge, within and across
// bodies) through the elementary tests of ccd.hpp only. Generated motions: two spheres passing
// through each other's path, a ball pressed onto a still box, a body resting on a still body
// (still against still skipped, yet a moving body touching a still one found), and the global
// and per-body position layouts giving identical contacts.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "tetseg/runtime/ccd.hpp"
#include "tetseg/runtime/scene.hpp"
#include "tetseg/testing/allocation_probe.hpp"
#include "tetseg/testing/scene_oracle.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using tetseg::BodyOptions;
using tetseg::BodyShape;
using tetseg::ColliderMode;
using tetseg::ColliderStatus;
using tetseg::Contact;
using tetseg::ContactKind;
using tetseg::ContactsResult;
using tetseg::EarliestContact;
using tetseg::test::box_surface;
using tetseg::test::P3;
using tetseg::test::Surface;

namespace {

/// One body of a test scene: its triangles over local node ids and its positions per frame.
struct TestBody {
  std::vector<tetseg::format::Triangle> tris;
  std::uint32_t node_count = 0;
  std::vector<std::vector<double>> frames;  // node_count * 3 per frame
  bool still = false;
  bool self = true;
  std::shared_ptr<const BodyShape> shape;
  std::shared_ptr<tetseg::test::Scene> tet;  // keeps a tet body's asset alive
};

using Map = std::function<P3(const P3&, double)>;

std::vector<std::vector<double>> frames_of(const std::vector<double>& rest, int count,
                                           const Map& map) {
  std::vector<std::vector<double>> out(count);
  for (int f = 0; f < count; ++f) {
    const double t = count > 1 ? double(f) / (count - 1) : 0.0;
    for (std::size_t n = 0; n < rest.size() / 3; ++n) {
      const P3 p = map({rest[3 * n], rest[3 * n + 1], rest[3 * n + 2]}, t);
      out[f].insert(out[f].end(), p.begin(), p.end());
    }
  }
  return out;
}

/// A tet body (asset with two clusters, rvbc inside) from a closed surface.
TestBody tet_body(const Surface& s, int frames, const Map& map) {
  TestBody b;
  b.tet = std::make_shared<tetseg::test::Scene>(
      tetseg::test::make_axial_scene(s, {0.0}, {-0.45, 0.45}));
  b.tris = s.tris;
  b.node_count = b.tet->asset.node_count();
  b.frames = frames_of(b.tet->rest, frames, map);
  b.shape = BodyShape::from_asset(b.tet->asset);
  return b;
}

/// A surface-only body (no asset) from a triangle mesh.
TestBody surface_body(const Surface& s, int frames, const Map& map) {
  TestBody b;
  b.tris = s.tris;
  b.node_count = static_cast<std::uint32_t>(s.verts.size());
  std::vector<double> rest;
  for (const P3& p : s.verts) rest.insert(rest.end(), p.begin(), p.end());
  b.frames = frames_of(rest, frames, map);
  std::vector<std::uint32_t> flat;
  for (const auto& t : s.tris) flat.insert(flat.end(), t.begin(), t.end());
  b.shape = BodyShape::from_triangles(flat.data(), s.tris.size(), b.node_count);
  return b;
}

Map translate(const P3& from, const P3& to) {
  return [from, to](const P3& p, double t) {
    return P3{p[0] + from[0] + t * (to[0] - from[0]), p[1] + from[1] + t * (to[1] - from[1]),
              p[2] + from[2] + t * (to[2] - from[2])};
  };
}

Map fixed(const P3& at) {
  return translate(at, at);
}

using Key = std::tuple<int, std::uint32_t, std::uint32_t, std::array<std::uint32_t, 4>>;
Key key_of(const Contact& c) {
  return {int(c.kind), c.bodies[0], c.bodies[1], c.nodes};
}

std::string describe(const Contact& c) {
  std::string s = c.kind == ContactKind::kVertexFace ? "vf" : "ee";
  s += " bodies " + std::to_string(c.bodies[0]) + "," + std::to_string(c.bodies[1]) + " nodes";
  for (auto n : c.nodes) s += " " + std::to_string(n);
  return s + " toi " + std::to_string(c.toi);
}

/// The oracle (tetseg/testing/scene_oracle.hpp) over step f of `bodies`.
std::vector<Contact> brute_contacts(const std::vector<TestBody>& bodies, int f) {
  std::vector<tetseg::test::OracleBody> oracle(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const TestBody& b = bodies[i];
    oracle[i].tris = b.tris.data();
    oracle[i].triangle_count = b.tris.size();
    oracle[i].x0 = b.frames[b.still ? 0 : f].data();
    oracle[i].x1 = b.frames[b.still ? 0 : f + 1].data();
    oracle[i].self = b.self;
  }
  return tetseg::test::scene_brute_contacts(oracle);
}

/// Builds the runtime scene over `bodies`; with `global`, all positions come from one array
/// (bodies in order, offsets = running node counts) copied into `global_frames`.
tetseg::Scene make_runtime_scene(const std::vector<TestBody>& bodies, bool global,
                                 std::vector<std::vector<double>>* global_frames = nullptr) {
  tetseg::Scene scene;
  std::size_t offset = 0;
  for (const TestBody& b : bodies) {
    REQUIRE(b.shape);
    BodyOptions o;
    o.still = b.still;
    o.self_collision = b.self;
    if (global) o.global_offset = offset;
    offset += b.node_count;
    REQUIRE(scene.add_body(b.shape, o) == ColliderStatus::kOk);
  }
  if (global) {
    const std::size_t frames = bodies.front().frames.size();
    global_frames->assign(frames, {});
    for (std::size_t f = 0; f < frames; ++f)
      for (const TestBody& b : bodies) {
        const auto& x = b.frames[b.still ? 0 : f];
        (*global_frames)[f].insert((*global_frames)[f].end(), x.begin(), x.end());
      }
  }
  return scene;
}

struct StepResult {
  bool any = false;
  EarliestContact earliest;
  std::vector<Contact> contacts;
};

StepResult run_step(tetseg::Scene& scene, const std::vector<TestBody>& bodies, int f,
                    const std::vector<std::vector<double>>* global_frames) {
  if (global_frames) {
    const auto& g0 = (*global_frames)[f];
    const auto& g1 = (*global_frames)[f + 1];
    REQUIRE(scene.step(g0.data(), g1.data(), g0.size()) == ColliderStatus::kOk);
  } else {
    for (std::uint32_t i = 0; i < bodies.size(); ++i) {
      const TestBody& b = bodies[i];
      const auto& x0 = b.frames[b.still ? 0 : f];
      const double* x1 = b.still ? nullptr : b.frames[f + 1].data();
      REQUIRE(scene.set_positions(i, x0.data(), x1, x0.size()) == ColliderStatus::kOk);
    }
    REQUIRE(scene.step() == ColliderStatus::kOk);
  }
  StepResult r;
  REQUIRE(scene.any_collision(r.any) == ColliderStatus::kOk);
  std::vector<Contact> buffer(1 << 15);
  ContactsResult cr;
  REQUIRE(scene.contacts(buffer.data(), buffer.size(), cr) == ColliderStatus::kOk);
  REQUIRE_FALSE(cr.truncated());
  buffer.resize(cr.written);
  r.contacts = buffer;
  REQUIRE(scene.earliest_toi(r.earliest) == ColliderStatus::kOk);
  CHECK(r.any == !r.contacts.empty());
  CHECK(r.earliest.found == r.any);
  return r;
}

/// Compares every step with the oracle: the same any-collision answer and earliest time of
/// impact, the same contacts between bodies and within surface-only bodies (overlap culling is
/// exact), and within tet bodies every oracle contact at the earliest toi (radial-view culling
/// guarantees the first contact). Stops after the first step with a self contact of a tet
/// body (the next one starts self-intersecting, which voids the culling guarantee). Returns
/// the number of steps with a contact.
int compare_with_oracle(const std::vector<TestBody>& bodies, bool global) {
  std::vector<std::vector<double>> global_frames;
  tetseg::Scene scene = make_runtime_scene(bodies, global, &global_frames);
  int contact_steps = 0;
  const int steps = static_cast<int>(bodies.front().frames.size()) - 1;
  for (int f = 0; f < steps; ++f) {
    CAPTURE(f);
    const StepResult got = run_step(scene, bodies, f, global ? &global_frames : nullptr);
    const std::vector<Contact> truth = brute_contacts(bodies, f);
    REQUIRE(got.any == !truth.empty());
    if (truth.empty()) continue;
    ++contact_steps;
    REQUIRE(got.earliest.found);
    CHECK(got.earliest.contact.toi == truth.front().toi);
    std::set<Key> found;
    for (const Contact& c : got.contacts) {
      CHECK(found.insert(key_of(c)).second);  // no contact twice
    }
    std::set<Key> truth_keys;
    for (const Contact& c : truth) truth_keys.insert(key_of(c));
    for (const Contact& c : got.contacts) {
      if (!truth_keys.count(key_of(c))) FAIL("contact not in the oracle: " << describe(c));
    }
    for (const Contact& c : truth) {
      const bool exact = c.bodies[0] != c.bodies[1] || !bodies[c.bodies[0]].tet;
      if ((exact || c.toi == truth.front().toi) && !found.count(key_of(c)))
        FAIL("missed contact: " << describe(c));
    }
    for (const Contact& c : truth)
      if (c.bodies[0] == c.bodies[1] && bodies[c.bodies[0]].tet) return contact_steps;
  }
  return contact_steps;
}

Surface small_sphere(double r = 1.0) {
  return tetseg::test::sphere(r, 12, 7);
}

}  // namespace

TEST_CASE("Scene: two spheres passing through each other's path", "[scene]") {
  // A tet body and a surface-only body cross with their centres 1.5 apart (radii 1).
  std::vector<TestBody> bodies;
  bodies.push_back(tet_body(small_sphere(), 9, translate({-3, 0, 0}, {3, 0.0, 0})));
  bodies.push_back(surface_body(small_sphere(), 9, translate({3, 1.5, 0.2}, {-3, 1.5, 0.2})));
  const int steps = compare_with_oracle(bodies, false);
  CHECK(steps >= 2);
  CHECK(compare_with_oracle(bodies, true) == steps);
}

TEST_CASE("Scene: a ball pressed onto a still box", "[scene]") {
  std::vector<TestBody> bodies;
  TestBody box = surface_body(box_surface({-2, -2, -1}, {2, 2, 0}, 4), 1, fixed({0, 0, 0}));
  box.still = true;
  box.self = false;
  bodies.push_back(box);
  // The ball comes down and flattens against the top of the box (z = 0).
  bodies.push_back(tet_body(small_sphere(), 9, [](const P3& p, double t) {
    const double z = p[2] + 1.6 - 1.0 * t;
    return P3{p[0] * (1 + 0.2 * t), p[1] * (1 + 0.2 * t), z};
  }));
  for (TestBody& b : bodies)
    if (b.frames.size() == 1) b.frames.resize(9, b.frames[0]);
  const int steps = compare_with_oracle(bodies, false);
  CHECK(steps >= 1);
  CHECK(compare_with_oracle(bodies, true) == steps);
}

TEST_CASE("Scene: still against still costs nothing, moving against still is found", "[scene]") {
  // Ground box (still), a ball resting 1e-3 above it (still), a ball dropping onto the
  // resting one.
  std::vector<TestBody> bodies;
  TestBody ground = surface_body(box_surface({-3, -3, -1}, {3, 3, 0}, 3), 1, fixed({0, 0, 0}));
  ground.still = true;
  ground.self = false;
  TestBody resting = tet_body(small_sphere(), 1, fixed({0, 0, 1.001}));
  resting.still = true;
  TestBody dropping = tet_body(small_sphere(), 7, translate({0.3, 0.2, 3.6}, {0.3, 0.2, 2.4}));
  for (TestBody* b : {&ground, &resting}) b->frames.resize(7, b->frames[0]);
  bodies = {ground, resting, dropping};
  const int steps = compare_with_oracle(bodies, false);
  CHECK(steps >= 1);
  CHECK(compare_with_oracle(bodies, true) == steps);

  tetseg::Scene scene = make_runtime_scene(bodies, false);
  bool any_contact = false;
  for (int f = 0; f + 1 < 7; ++f) {
    const StepResult r = run_step(scene, bodies, f, nullptr);
    // The still pair (ground, resting) and both still bodies' self tests cost nothing.
    CHECK(scene.pair_stats(0, 1).node_pairs_visited == 0);
    CHECK(scene.pair_stats(0, 1).feature_tests == 0);
    CHECK(scene.body_stats(0).node_pairs_visited == 0);
    CHECK(scene.body_stats(1).node_pairs_visited == 0);
    CHECK(scene.stats().body_pairs_skipped >= 1);
    for (const Contact& c : r.contacts) {
      CHECK((c.bodies[0] == 2 || c.bodies[1] == 2));  // every contact involves the moving ball
      any_contact = true;
    }
  }
  CHECK(any_contact);
  CHECK(scene.pair_stats(1, 2).node_pairs_visited > 0);
}

TEST_CASE("Scene: a pressed tet body's self contact beside a passing body", "[scene]") {
  // Self contact inside a tet body (poles pressed together) while a surface-only sphere passes
  // close by: self and inter-body contacts in one query.
  std::vector<TestBody> bodies;
  bodies.push_back(surface_body(small_sphere(0.5), 13, translate({2.5, 0, 0.2}, {0.4, 0, 0.2})));
  bodies.push_back(tet_body(small_sphere(), 13, tetseg::test::press_poles));
  const int steps = compare_with_oracle(bodies, false);
  CHECK(steps >= 1);
  CHECK(compare_with_oracle(bodies, true) == steps);
}

TEST_CASE("Scene: global and per-body layouts give identical contacts", "[scene]") {
  std::vector<TestBody> bodies;
  bodies.push_back(tet_body(small_sphere(), 7, translate({-2.2, 0, 0}, {0.2, 0, 0})));
  bodies.push_back(surface_body(small_sphere(0.8), 7, translate({2.2, 0.3, 0}, {-0.1, 0.3, 0})));
  bodies.push_back(tet_body(small_sphere(), 7, translate({0, 0.2, 3.0}, {0, 0.2, 1.2})));
  std::vector<std::vector<double>> global_frames;
  tetseg::Scene own = make_runtime_scene(bodies, false);
  tetseg::Scene global = make_runtime_scene(bodies, true, &global_frames);
  std::size_t total = 0;
  for (int f = 0; f + 1 < 7; ++f) {
    const StepResult a = run_step(own, bodies, f, nullptr);
    const StepResult b = run_step(global, bodies, f, &global_frames);
    REQUIRE(a.contacts.size() == b.contacts.size());
    for (std::size_t i = 0; i < a.contacts.size(); ++i) {
      CHECK(key_of(a.contacts[i]) == key_of(b.contacts[i]));
      CHECK(a.contacts[i].toi == b.contacts[i].toi);
    }
    total += a.contacts.size();
  }
  CHECK(total > 0);
}

TEST_CASE("Scene: switches per body and per pair", "[scene]") {
  std::vector<TestBody> bodies;
  bodies.push_back(tet_body(small_sphere(), 5, translate({-2.5, 0, 0}, {0.5, 0, 0})));
  bodies.push_back(surface_body(small_sphere(), 5, translate({2.5, 0, 0}, {-0.5, 0, 0})));
  tetseg::Scene scene = make_runtime_scene(bodies, false);
  REQUIRE(scene.set_pair_enabled(0, 1, false) == ColliderStatus::kOk);
  CHECK(scene.set_pair_enabled(1, 1, false) == ColliderStatus::kInvalidArgument);
  CHECK(scene.set_pair_enabled(0, 2, false) == ColliderStatus::kInvalidArgument);
  CHECK(scene.set_self_collision(2, false) == ColliderStatus::kInvalidArgument);
  bool any_disabled = false;
  for (int f = 0; f + 1 < 5; ++f)
    any_disabled = any_disabled || run_step(scene, bodies, f, nullptr).any;
  CHECK_FALSE(any_disabled);  // rigid spheres: only contacts between them, and that is off
  REQUIRE(scene.set_pair_enabled(1, 0, true) == ColliderStatus::kOk);
  bool any_enabled = false;
  for (int f = 0; f + 1 < 5; ++f)
    any_enabled = any_enabled || run_step(scene, bodies, f, nullptr).any;
  CHECK(any_enabled);
}

TEST_CASE("Scene queries report failures as statuses, never as no contact", "[scene][api]") {
  std::vector<TestBody> bodies;
  bodies.push_back(tet_body(small_sphere(), 3, translate({-1.5, 0, 0}, {1.5, 0, 0})));
  bodies.push_back(surface_body(small_sphere(), 3, translate({1.5, 0, 0}, {-1.5, 0, 0})));
  auto require_queries = [](tetseg::Scene& s, ColliderStatus expected) {
    bool hit = true;
    CHECK(s.any_collision(hit) == expected);
    EarliestContact e;
    e.found = true;
    CHECK(s.earliest_toi(e) == expected);
    ContactsResult r;
    r.found = 3;
    std::vector<Contact> buffer(8);
    CHECK(s.contacts(buffer.data(), buffer.size(), r) == expected);
    if (expected != ColliderStatus::kOk) {
      CHECK_FALSE(hit);
      CHECK_FALSE(e.found);
      CHECK(r.found == 0);
      CHECK(r.written == 0);
    }
  };
  std::vector<std::vector<double>> global_frames;
  tetseg::Scene own = make_runtime_scene(bodies, false);
  tetseg::Scene global = make_runtime_scene(bodies, true, &global_frames);
  const auto& b0 = bodies[0].frames;
  const auto& b1 = bodies[1].frames;
  SECTION("No step") {
    require_queries(own, ColliderStatus::kNoStep);
    CHECK(own.step() == ColliderStatus::kNullInput);  // positions never set
    require_queries(own, ColliderStatus::kNoStep);
  }
  SECTION("A good step, then rejected steps drop it") {
    REQUIRE(own.set_positions(0, b0[0].data(), b0[2].data(), b0[0].size()) == ColliderStatus::kOk);
    REQUIRE(own.set_positions(1, b1[0].data(), b1[2].data(), b1[0].size()) == ColliderStatus::kOk);
    REQUIRE(own.step() == ColliderStatus::kOk);
    require_queries(own, ColliderStatus::kOk);
    bool hit = false;
    REQUIRE(own.any_collision(hit) == ColliderStatus::kOk);
    CHECK(hit);
    CHECK(own.set_positions(1, b1[0].data(), b1[2].data(), 5) == ColliderStatus::kSizeMismatch);
    CHECK(own.set_positions(7, b1[0].data(), b1[2].data(), 5) == ColliderStatus::kInvalidArgument);
    // New positions end the step: no answer from the arrays the step read.
    REQUIRE(own.set_positions(1, b1[0].data(), b1[2].data(), b1[0].size()) == ColliderStatus::kOk);
    require_queries(own, ColliderStatus::kNoStep);
    REQUIRE(own.step() == ColliderStatus::kOk);
    require_queries(own, ColliderStatus::kOk);
    REQUIRE(own.set_positions(1, b1[0].data(), nullptr, b1[0].size()) == ColliderStatus::kOk);
    require_queries(own, ColliderStatus::kNoStep);
    CHECK(own.step() == ColliderStatus::kNullInput);
    require_queries(own, ColliderStatus::kNoStep);
    std::vector<double> bad = b1[2];
    bad[5] = std::nan("");
    REQUIRE(own.set_positions(1, b1[0].data(), bad.data(), b1[0].size()) == ColliderStatus::kOk);
    CHECK(own.step() == ColliderStatus::kNonFinite);
    require_queries(own, ColliderStatus::kNoStep);
  }
  SECTION("Global layout: null arrays, short arrays, NaN") {
    const auto& g0 = global_frames[0];
    const auto& g2 = global_frames[2];
    CHECK(global.set_positions(0, g0.data(), g2.data(), b0[0].size()) ==
          ColliderStatus::kInvalidArgument);
    CHECK(global.step(nullptr, g2.data(), g0.size()) == ColliderStatus::kNullInput);
    require_queries(global, ColliderStatus::kNoStep);
    CHECK(global.step(g0.data(), g2.data(), g0.size() - 3) == ColliderStatus::kSizeMismatch);
    require_queries(global, ColliderStatus::kNoStep);
    std::vector<double> bad = g2;
    bad[bad.size() - 2] = INFINITY;
    CHECK(global.step(g0.data(), bad.data(), g0.size()) == ColliderStatus::kNonFinite);
    require_queries(global, ColliderStatus::kNoStep);
    REQUIRE(global.step(g0.data(), g2.data(), g0.size()) == ColliderStatus::kOk);
    require_queries(global, ColliderStatus::kOk);
  }
  SECTION("A forced traversal overflow is kOverflow") {
    tetseg::SceneOptions so;
    so.traversal_stack = 1;
    tetseg::Scene tiny(so);
    for (const TestBody& b : bodies) {
      BodyOptions o;
      o.self_collision = false;  // the overflow must come from the inter-body traversal
      REQUIRE(tiny.add_body(b.shape, o) == ColliderStatus::kOk);
    }
    REQUIRE(tiny.set_positions(0, b0[0].data(), b0[2].data(), b0[0].size()) == ColliderStatus::kOk);
    REQUIRE(tiny.set_positions(1, b1[0].data(), b1[2].data(), b1[0].size()) == ColliderStatus::kOk);
    REQUIRE(tiny.step() == ColliderStatus::kOk);
    require_queries(tiny, ColliderStatus::kOverflow);
    REQUIRE(tiny.set_self_collision(0, true) == ColliderStatus::kOk);
    REQUIRE(tiny.set_pair_enabled(0, 1, false) == ColliderStatus::kOk);
    require_queries(tiny, ColliderStatus::kOverflow);  // now from body 0's self traversal
  }
  SECTION("Bad bodies") {
    tetseg::Scene s;
    CHECK(s.add_body(nullptr, {}) == ColliderStatus::kInvalidArgument);
    BodyOptions brute;
    brute.mode = ColliderMode::kBrute;
    CHECK(s.add_body(bodies[0].shape, brute) == ColliderStatus::kInvalidArgument);
    const std::uint32_t bad_tri[3] = {0, 1, 9};
    CHECK_FALSE(BodyShape::from_triangles(bad_tri, 1, 9));
    const std::uint32_t degenerate[3] = {0, 1, 1};
    CHECK_FALSE(BodyShape::from_triangles(degenerate, 1, 9));
  }
}

TEST_CASE("Scene steps and queries allocate nothing", "[scene][alloc]") {
  std::vector<TestBody> bodies;
  bodies.push_back(tet_body(small_sphere(), 5, translate({-2, 0, 0}, {1, 0, 0})));
  bodies.push_back(surface_body(small_sphere(), 5, translate({2, 0.5, 0}, {-1, 0.5, 0})));
  TestBody still = surface_body(box_surface({-3, -3, -2}, {3, 3, -1}, 2), 5, fixed({0, 0, 0}));
  still.still = true;
  bodies.push_back(still);
  std::vector<std::vector<double>> global_frames;
  tetseg::Scene scene = make_runtime_scene(bodies, true, &global_frames);
  std::vector<Contact> buffer(4096);
  std::size_t contacts = 0;
  for (std::size_t f = 0; f + 1 < global_frames.size(); ++f) {
    tetseg::test::AllocationProbe probe;
    const auto& g0 = global_frames[f];
    REQUIRE(scene.step(g0.data(), global_frames[f + 1].data(), g0.size()) == ColliderStatus::kOk);
    bool hit = false;
    REQUIRE(scene.any_collision(hit) == ColliderStatus::kOk);
    EarliestContact e;
    REQUIRE(scene.earliest_toi(e) == ColliderStatus::kOk);
    ContactsResult r;
    REQUIRE(scene.contacts(buffer.data(), buffer.size(), r) == ColliderStatus::kOk);
    contacts += r.found;
    CHECK(probe.count() == 0);
  }
  CHECK(contacts > 0);
}

TEST_CASE("Scene: neighbouring triangles folding through each other", "[scene][plane]") {
  // Triangles sharing an edge (a hinge closing past flat) and sharing one vertex (a fan
  // swinging through). A surface-only body (whole-surface BVH) never examines triangle pairs
  // that share a node: their touching feature pairs come from the orphan sets.
  TestBody hinge;
  hinge.tris = {{0, 1, 2}, {1, 0, 3}, {0, 4, 5}};
  hinge.node_count = 6;
  const int frames = 9;
  for (int f = 0; f < frames; ++f) {
    const double t = double(f) / (frames - 1);
    const double a = (2.2 - 2.9 * t);  // hinge angle (radians) about the x axis
    const double b = (1.3 - 2.6 * t);  // fan angle about the y axis through node 0
    hinge.frames.push_back({0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.4, 0.6 * std::cos(a), 0.6 * std::sin(a),
                            0.7 * std::cos(b), 0.3, 0.7 * std::sin(b), 0.7 * std::cos(b), 0.5,
                            0.7 * std::sin(b) + 0.05});
  }
  std::vector<std::uint32_t> flat;
  for (const auto& t : hinge.tris) flat.insert(flat.end(), t.begin(), t.end());
  hinge.shape = BodyShape::from_triangles(flat.data(), hinge.tris.size(), hinge.node_count);
  const std::vector<TestBody> bodies{hinge};
  CHECK(compare_with_oracle(bodies, false) >= 2);
  tetseg::Scene scene = make_runtime_scene(bodies, false);
  std::uint64_t pairs = 0, feature_pairs = 0;
  for (int f = 0; f + 1 < frames; ++f) {
    run_step(scene, bodies, f, nullptr);
    pairs += scene.body_stats(0).triangle_pairs;
    feature_pairs += scene.body_stats(0).feature_pairs;
  }
  CHECK(pairs == 0);         // every pair of the three triangles shares node 0
  CHECK(feature_pairs > 0);  // the orphan feature pairs were examined
}

TEST_CASE("Scene: random hinges tumbling through each other against the oracle", "[scene][plane]") {
  // Two surface-only bodies, each a hinge of two triangles sharing an edge (so every edge and
  // vertex has a neighbouring triangle's plane), rotating and passing through each other on
  // random paths: the triangle-pair and feature-pair plane filters (docs/runtime.md) must drop
  // no contact that brute force finds.
  std::mt19937 rng(11);
  auto u = [&] { return (rng() / 4294967296.0) * 2 - 1; };
  int contact_steps = 0;
  for (int trial = 0; trial < 300; ++trial) {
    CAPTURE(trial);
    std::vector<TestBody> bodies;
    for (int b = 0; b < 2; ++b) {
      Surface s;
      s.verts = {
          {-0.5, 0, 0}, {0.5, 0, 0}, {0.3 * u(), 0.8, 0.4 * u()}, {0.3 * u(), -0.8, 0.4 * u()}};
      s.tris = {{0, 1, 2}, {1, 0, 3}};
      P3 axis{u(), u(), u()};
      const double len = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
      for (double& c : axis) c /= std::max(len, 1e-3);
      const double angle0 = 3 * u(), turn = 1.5 * u();
      const double side = b == 0 ? 0.0 : 1.0;
      const P3 from{side * 0.3 * u(), side * 0.3 * u(), side * -1.2};
      const P3 to{side * 0.3 * u(), side * 0.3 * u(), side * (0.2 + 0.6 * u())};
      Map move = [axis, angle0, turn, from, to](const P3& p, double t) {
        // Rodrigues rotation by angle0 + t * turn about `axis`, then the path.
        const double a = angle0 + t * turn, c = std::cos(a), sn = std::sin(a);
        const double d = axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
        const P3 x{axis[1] * p[2] - axis[2] * p[1], axis[2] * p[0] - axis[0] * p[2],
                   axis[0] * p[1] - axis[1] * p[0]};
        P3 r;
        for (int k = 0; k < 3; ++k)
          r[k] = p[k] * c + x[k] * sn + axis[k] * d * (1 - c) + from[k] + t * (to[k] - from[k]);
        return r;
      };
      bodies.push_back(surface_body(s, 4, move));
    }
    contact_steps += compare_with_oracle(bodies, trial % 2 == 0);
  }
  CHECK(contact_steps >= 100);
}

TEST_CASE("Scene: OpenMP results equal serial results", "[scene][openmp]") {
  // Six balls in a squeezing ring: many body pairs traversed at once.
  std::vector<TestBody> bodies;
  for (int b = 0; b < 6; ++b) {
    const double a = b * M_PI / 3;
    const P3 from{2.4 * std::cos(a), 2.4 * std::sin(a), 0.1 * b};
    const P3 to{1.7 * std::cos(a), 1.7 * std::sin(a), 0.1 * b};
    bodies.push_back(b % 2 ? surface_body(small_sphere(), 6, translate(from, to))
                           : tet_body(small_sphere(), 6, translate(from, to)));
  }
  std::vector<std::vector<double>> global_frames;
  tetseg::Scene serial = make_runtime_scene(bodies, true, &global_frames);
  tetseg::SceneOptions po;
  po.use_openmp = true;
  tetseg::Scene parallel(po);
  std::size_t offset = 0;
  for (const TestBody& b : bodies) {
    BodyOptions o;
    o.global_offset = offset;
    offset += b.node_count;
    REQUIRE(parallel.add_body(b.shape, o) == ColliderStatus::kOk);
  }
  std::size_t total = 0;
  int parallel_steps = 0;
  for (std::size_t f = 0; f + 1 < global_frames.size(); ++f) {
    const auto& g0 = global_frames[f];
    const auto& g1 = global_frames[f + 1];
    for (tetseg::Scene* s : {&serial, &parallel})
      REQUIRE(s->step(g0.data(), g1.data(), g0.size()) == ColliderStatus::kOk);
    bool hs = false, hp = false;
    REQUIRE(serial.any_collision(hs) == ColliderStatus::kOk);
    REQUIRE(parallel.any_collision(hp) == ColliderStatus::kOk);
    CHECK(hs == hp);
    for (tetseg::Scene* s : {&serial, &parallel})
      REQUIRE(s->step(g0.data(), g1.data(), g0.size()) == ColliderStatus::kOk);
    EarliestContact es, ep;
    REQUIRE(serial.earliest_toi(es) == ColliderStatus::kOk);
    REQUIRE(parallel.earliest_toi(ep) == ColliderStatus::kOk);
    REQUIRE(es.found == ep.found);
    if (es.found) {
      CHECK(key_of(es.contact) == key_of(ep.contact));
      CHECK(es.contact.toi == ep.contact.toi);
    }
    ContactsResult rs, rp;
    REQUIRE(serial.contacts(nullptr, 0, rs) == ColliderStatus::kOk);
    REQUIRE(parallel.contacts(nullptr, 0, rp) == ColliderStatus::kOk);
    CHECK(rs.found == rp.found);
    CHECK(serial.stats().pair_threads == 1);
    parallel_steps += parallel.stats().pair_threads > 1 ? 1 : 0;
    CHECK(serial.stats().body_pairs_tested == parallel.stats().body_pairs_tested);
    for (std::uint32_t a = 0; a < bodies.size(); ++a)
      for (std::uint32_t b = a + 1; b < bodies.size(); ++b) {
        CHECK(serial.pair_stats(a, b).feature_tests == parallel.pair_stats(a, b).feature_tests);
        CHECK(serial.pair_stats(a, b).contacts == parallel.pair_stats(a, b).contacts);
      }
    total += rs.found;
  }
  CHECK(total > 0);
  REQUIRE(parallel_steps > 0);  // parallel against serial, not serial twice
}

TEST_CASE("Scene: random wobbling bodies against the oracle", "[scene][random]") {
  // Three moving bodies (two tet, one surface-only) with random paths towards each other and
  // random smooth wobbles, above a still box they may reach: every layout, several seeds.
  for (unsigned seed : {1u, 2u, 3u}) {
    CAPTURE(seed);
    std::mt19937 rng(seed);
    auto u = [&] { return (rng() / 4294967296.0) * 2 - 1; };
    std::vector<TestBody> bodies;
    TestBody box = surface_body(box_surface({-3, -3, -2.2}, {3, 3, -1.2}, 3), 1, fixed({0, 0, 0}));
    box.still = true;
    box.self = false;
    box.frames.resize(7, box.frames[0]);
    bodies.push_back(box);
    for (int b = 0; b < 3; ++b) {
      const double a = 2 * M_PI * b / 3 + 0.3 * u();
      const P3 from{2.3 * std::cos(a), 2.3 * std::sin(a), 0.3 * u()};
      const P3 to{0.9 * std::cos(a) + 0.3 * u(), 0.9 * std::sin(a) + 0.3 * u(), -0.4 + 0.3 * u()};
      const double k[3] = {2 + u(), 2 + u(), 2 + u()}, phase = 3 * u(), amp = 0.08 * (1 + u());
      Map move = [from, to, k, phase, amp](const P3& p, double t) {
        const double w = 1 + amp * t * std::sin(k[0] * p[0] + k[1] * p[1] + k[2] * p[2] + phase);
        return P3{from[0] + t * (to[0] - from[0]) + w * p[0],
                  from[1] + t * (to[1] - from[1]) + w * p[1],
                  from[2] + t * (to[2] - from[2]) + w * p[2]};
      };
      bodies.push_back(b == 1 ? surface_body(small_sphere(0.8), 7, move)
                              : tet_body(small_sphere(0.8), 7, move));
    }
    const int steps = compare_with_oracle(bodies, seed % 2 == 0);
    CHECK(steps >= 1);
  }
}

TEST_CASE("Scene: the start-state check finds bodies that intersect", "[scene][rest]") {
  // Body 0: a tet sphere, body 1: a surface sphere. Frame 0: apart; frame 1: overlapping;
  // body 0 also pressed through itself at frame 1 (its poles passed each other).
  std::vector<TestBody> bodies;
  bodies.push_back(tet_body(small_sphere(), 2,
                            [](const P3& p, double t) { return tetseg::test::press_poles(p, t); }));
  bodies.push_back(surface_body(small_sphere(), 2, translate({3, 0, 0}, {1.5, 0, 0})));
  std::vector<std::vector<double>> global_frames;
  tetseg::Scene scene = make_runtime_scene(bodies, true, &global_frames);
  const auto& apart = global_frames[0];
  const auto& overlap = global_frames[1];
  tetseg::RestCheck r = scene.check_rest_intersection(apart.data(), apart.size());
  REQUIRE(r.status == ColliderStatus::kOk);
  CHECK_FALSE(r.intersecting);
  r = scene.check_rest_intersection(overlap.data(), overlap.size());
  REQUIRE(r.status == ColliderStatus::kOk);
  REQUIRE(r.intersecting);
  CHECK(r.bodies[0] == 0);
  CHECK(r.bodies[1] == 0);  // body 0's self intersection comes first
  REQUIRE(scene.set_self_collision(0, false) == ColliderStatus::kOk);
  r = scene.check_rest_intersection(overlap.data(), overlap.size());
  REQUIRE(r.status == ColliderStatus::kOk);
  REQUIRE(r.intersecting);
  CHECK(r.bodies[0] == 0);
  CHECK(r.bodies[1] == 1);
  CHECK(r.triangle_a < bodies[0].tris.size());
  CHECK(r.triangle_b < bodies[1].tris.size());
  REQUIRE(scene.set_pair_enabled(0, 1, false) == ColliderStatus::kOk);
  r = scene.check_rest_intersection(overlap.data(), overlap.size());
  REQUIRE(r.status == ColliderStatus::kOk);
  CHECK_FALSE(r.intersecting);
  CHECK(scene.check_rest_intersection(nullptr, apart.size()).status == ColliderStatus::kNullInput);
  CHECK(scene.check_rest_intersection(apart.data(), apart.size() - 3).status ==
        ColliderStatus::kSizeMismatch);
  // The check reuses the step scratch: queries need a new step.
  bool hit = false;
  CHECK(scene.any_collision(hit) == ColliderStatus::kNoStep);
  REQUIRE(scene.step(apart.data(), overlap.data(), apart.size()) == ColliderStatus::kOk);
  REQUIRE(scene.any_collision(hit) == ColliderStatus::kOk);
}
