#pragma once
// Runs a frame sequence through the collider in several modes and compares every mode, brute
// included, with the scene oracle (tetseg/testing/scene_oracle.hpp: its own feature
// enumeration and the elementary tests alone, no collider code) and with exact rational truth
// (exact_scene_oracle.hpp). Per step: every exact contact is an oracle contact no later than
// the exact time; every mode contact is an oracle contact at the same toi (subset: nothing
// invented); every exactly confirmed contact at the earliest toi is found (by bvh, brute and
// cone: every one), and the any-collision answers agree. Used by tests/runtime/collider*_test.cpp,
// cross_cluster, wide_bvh and detector_point tests.

#include <algorithm>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "runtime/support/queries.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/exact_scene_oracle.hpp"
#include "tetseg/testing/scene_oracle.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

namespace tetseg::test {

inline bool same_feature(const Contact& a, const Contact& b) {
  return a.kind == b.kind && a.nodes == b.nodes;
}

inline std::string describe(const Contact& c) {
  std::string s = c.kind == ContactKind::kVertexFace ? "vf " : "ee ";
  for (auto n : c.nodes) s += std::to_string(n) + " ";
  return s + "toi " + std::to_string(c.toi);
}

/// A collider in `mode` with default options over the scene's asset (which must outlive it).
inline Collider collider_for(const Scene& scene, ColliderMode mode) {
  ColliderOptions options;
  options.mode = mode;
  return Collider(scene.asset, options);
}

struct StepAnswer {
  bool any = false;
  EarliestContact earliest;
  std::vector<Contact> contacts;
};

inline StepAnswer answer(Collider& collider, const double* x0, const double* x1) {
  StepAnswer a;
  REQUIRE(collider.step(x0, x1) == ColliderStatus::kOk);
  a.any = any_ok(collider);  // early-exit path first
  std::vector<Contact> buffer(1 << 16);
  const ContactsResult r = contacts_ok(collider, buffer.data(), buffer.size());
  REQUIRE_FALSE(r.truncated());
  buffer.resize(r.written);
  a.contacts = buffer;
  a.earliest = earliest_ok(collider);
  CHECK(a.any == !a.contacts.empty());
  CHECK(a.earliest.found == a.any);
  // No feature pair is reported twice (deduplication over all non-culled pairs).
  for (std::size_t i = 1; i < a.contacts.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (same_feature(a.contacts[i], a.contacts[j]))
        FAIL("duplicate contact " << describe(a.contacts[i]));
    }
  }
  return a;
}

struct SequenceReport {
  int frames_compared = 0;
  int contact_frames = 0;  // steps with an exact contact
  std::uint64_t orientation_culled = 0;
  std::uint64_t clusters_skipped = 0;
  std::uint64_t closure_pairs = 0;  // rvbc contact-closure pairs over the compared steps
  std::uint64_t rvbc_tests = 0, brute_tests = 0;
  std::vector<Contact> first_contacts;
  /// Earliest contacts whose feature pair also lies in an orientation-culled triangle pair
  /// (same cluster, same definite class): the design note's wedge-tip situation, where the
  /// pair must be tested from another, non-culled triangle pair.
  int wedge_contacts = 0;  // required contacts at the earliest toi of the first contact frame
};

/// Does a triangle pair containing the feature pair of `c` have the same definite class in
/// the same cluster (i.e. is it culled by orientation in the collider's current step)?
inline bool in_culled_pair(const Collider& rvbc, const Scene& scene, const Contact& c) {
  const format::Asset& a = scene.asset.data();
  auto has = [&](std::size_t t, std::uint32_t n) {
    return a.triangles[t][0] == n || a.triangles[t][1] == n || a.triangles[t][2] == n;
  };
  std::vector<std::size_t> f1, f2;
  for (std::size_t t = 0; t < a.triangles.size(); ++t) {
    if (c.kind == ContactKind::kVertexFace) {
      if (has(t, c.nodes[0])) f1.push_back(t);
    } else {
      if (has(t, c.nodes[0]) && has(t, c.nodes[1])) f1.push_back(t);
      if (has(t, c.nodes[2]) && has(t, c.nodes[3])) f2.push_back(t);
    }
  }
  if (c.kind == ContactKind::kVertexFace) f2.push_back(c.triangle);
  for (std::size_t t1 : f1)
    for (std::size_t t2 : f2) {
      const Orientation o = rvbc.triangle_class(t1);
      if (a.triangle_cluster[t1] == a.triangle_cluster[t2] && o != Orientation::kUncertain &&
          o == rvbc.triangle_class(t2))
        return true;
    }
  return false;
}

/// The collider's one body for the oracles (self-collision on) over the step x0 -> x1.
inline OracleBody oracle_body(const Scene& scene, const double* x0, const double* x1) {
  const format::Asset& a = scene.asset.data();
  return OracleBody{a.triangles.data(), a.triangles.size(), x0, x1, true};
}

/// The oracle's contacts of the step, sorted.
inline std::vector<Contact> oracle_contacts(const Scene& scene, const double* x0,
                                            const double* x1) {
  return scene_brute_contacts({oracle_body(scene, x0, x1)});
}

/// The truth of one step: the oracle's contacts (the runtime's elementary tests on every
/// feature pair: conservative, so they may include near misses) and the exact contacts
/// (exact_scene_oracle.hpp), both sorted.
struct StepTruth {
  std::vector<Contact> oracle, exact;
  /// The oracle contacts that exact arithmetic confirms, sorted: what no mode may miss.
  std::vector<Contact> required;
};

/// Computes the truth of a step and requires every exact contact to be an oracle contact at a
/// toi no later than the exact one (the elementary tests miss nothing, never report late).
inline StepTruth step_truth(const OracleBody& body) {
  StepTruth t;
  t.oracle = scene_brute_contacts({body});
  t.exact = scene_exact_contacts({body});
  for (const Contact& e : t.exact) {
    CAPTURE(describe(e));
    const auto it = std::find_if(t.oracle.begin(), t.oracle.end(),
                                 [&](const Contact& o) { return same_feature(o, e); });
    REQUIRE(it != t.oracle.end());
    REQUIRE(it->toi <= e.toi);
    if (e.at_start) REQUIRE(it->at_start);
    t.required.push_back(*it);
  }
  std::sort(t.required.begin(), t.required.end(), contact_less);
  return t;
}

inline StepTruth step_truth(const Scene& scene, const double* x0, const double* x1) {
  return step_truth(oracle_body(scene, x0, x1));
}

/// What a mode must report against the truth.
enum class Expect {
  kAllContacts,       ///< every required contact (bvh, brute, cone)
  kEarliestContacts,  ///< the required contacts up to the earliest (rvbc)
};

/// A mode's answer against the truth: nothing outside the oracle's contacts and at their
/// times (the runtime's filters may only drop near misses that exact arithmetic rejects),
/// every required contact up to the earliest required toi (all of them for kAllContacts),
/// the earliest toi never after it, and any-collision true whenever something is required.
inline void require_matches_oracle(const StepAnswer& m, const StepTruth& truth, Expect expect) {
  constexpr double kTol = 1e-9;  // contacts this close to the earliest toi must be found
  const std::vector<Contact>& oracle = truth.oracle;
  if (oracle.empty()) REQUIRE_FALSE(m.any);
  for (const Contact& c : m.contacts) {  // subset, at the same times
    CAPTURE(describe(c));
    const auto it = std::find_if(oracle.begin(), oracle.end(),
                                 [&](const Contact& o) { return same_feature(o, c); });
    REQUIRE(it != oracle.end());
    REQUIRE(c.toi == it->toi);
    REQUIRE(c.at_start == it->at_start);
  }
  if (truth.required.empty()) return;
  REQUIRE(m.any);
  REQUIRE(m.earliest.found);
  const double earliest = truth.required.front().toi;
  REQUIRE(m.earliest.contact.toi <= earliest);
  for (const Contact& o : truth.required) {
    if (expect == Expect::kEarliestContacts && o.toi > earliest + kTol) break;
    CAPTURE(describe(o));
    REQUIRE(std::any_of(m.contacts.begin(), m.contacts.end(),
                        [&](const Contact& x) { return same_feature(x, o); }));
  }
}

/// Compares brute, bvh and rvbc with the oracle on every step until (and including) the first
/// step with a contact: after it the surface may start a step self-intersecting, which voids
/// rvbc's culling guarantee (design note), so later steps are not compared (unless
/// `stop_at_first_contact` is false).
inline SequenceReport compare_with_oracle(const Scene& scene,
                                          const std::vector<std::vector<double>>& frames,
                                          bool stop_at_first_contact = true) {
  Collider rvbc = collider_for(scene, ColliderMode::kRvbc);
  Collider bvh = collider_for(scene, ColliderMode::kBvh);
  Collider brute = collider_for(scene, ColliderMode::kBrute);
  REQUIRE(rvbc.status() == ColliderStatus::kOk);
  SequenceReport rep;
  constexpr double kTol = 1e-9;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    CAPTURE(f);
    const double* x0 = frames[f].data();
    const double* x1 = frames[f + 1].data();
    const StepTruth truth = step_truth(scene, x0, x1);
    const std::vector<Contact>& oracle = truth.oracle;
    const StepAnswer b = answer(brute, x0, x1);
    const StepAnswer r = answer(rvbc, x0, x1);
    const StepAnswer g = answer(bvh, x0, x1);
    rep.orientation_culled += rvbc.stats().node_pairs_orientation_culled;
    rep.clusters_skipped += rvbc.stats().clusters_skipped;
    rep.closure_pairs += rvbc.stats().closure_pairs;
    rep.rvbc_tests += rvbc.stats().feature_tests;
    rep.brute_tests += brute.stats().feature_tests;
    ++rep.frames_compared;
    {
      INFO("brute");
      require_matches_oracle(b, truth, Expect::kAllContacts);
    }
    {
      INFO("bvh");
      require_matches_oracle(g, truth, Expect::kAllContacts);
    }
    {
      INFO("rvbc");
      require_matches_oracle(r, truth, Expect::kEarliestContacts);
    }
    if (oracle.empty()) continue;
    if (!truth.required.empty()) ++rep.contact_frames;  // an exact contact is reached
    for (const Contact& c : truth.required) {
      if (c.toi > truth.required.front().toi + kTol) break;
      if (rep.contact_frames == 1) rep.first_contacts.push_back(c);
      if (in_culled_pair(rvbc, scene, c)) ++rep.wedge_contacts;
    }
    if (stop_at_first_contact) break;
  }
  return rep;
}

}  // namespace tetseg::test
