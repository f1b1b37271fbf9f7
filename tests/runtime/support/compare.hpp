#pragma once
// Runs a frame sequence through the collider in several modes and compares with brute force
// (the oracle): same any-collision answer each frame, and every brute-force contact at the
// earliest time of impact also found. Used by tests/runtime/collider*_test.cpp.

#include <algorithm>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "runtime/support/queries.hpp"
#include "tetseg/runtime/collider.hpp"
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
  int contact_frames = 0;
  std::uint64_t orientation_culled = 0;
  std::uint64_t clusters_skipped = 0;
  std::uint64_t closure_pairs = 0;  // rvbc contact-closure pairs over the compared steps
  std::uint64_t rvbc_tests = 0, brute_tests = 0;
  std::vector<Contact> first_contacts;
  /// Earliest contacts whose feature pair also lies in an orientation-culled triangle pair
  /// (same cluster, same definite class): the design note's wedge-tip situation, where the
  /// pair must be tested from another, non-culled triangle pair.
  int wedge_contacts = 0;  // brute contacts at the earliest toi of the first contact frame
};

/// Compares rvbc and bvh with brute on every step until (and including) the first step with a
/// contact: after it the surface may start a step self-intersecting, which voids the culling
/// guarantee (design note), so later steps are not compared.
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

inline SequenceReport compare_with_brute(const Scene& scene,
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
    const StepAnswer b = answer(brute, frames[f].data(), frames[f + 1].data());
    const StepAnswer r = answer(rvbc, frames[f].data(), frames[f + 1].data());
    const StepAnswer g = answer(bvh, frames[f].data(), frames[f + 1].data());
    rep.orientation_culled += rvbc.stats().node_pairs_orientation_culled;
    rep.clusters_skipped += rvbc.stats().clusters_skipped;
    rep.closure_pairs += rvbc.stats().closure_pairs;
    rep.rvbc_tests += rvbc.stats().feature_tests;
    rep.brute_tests += brute.stats().feature_tests;
    ++rep.frames_compared;
    REQUIRE(r.any == b.any);
    REQUIRE(g.any == b.any);
    // bvh has no orientation culling: exactly the brute-force contact set.
    REQUIRE(g.contacts.size() == b.contacts.size());
    for (std::size_t i = 0; i < b.contacts.size(); ++i) {
      CAPTURE(describe(b.contacts[i]));
      REQUIRE(same_feature(g.contacts[i], b.contacts[i]));
    }
    if (!b.any) continue;
    ++rep.contact_frames;
    REQUIRE(r.earliest.found);
    CHECK(r.earliest.contact.toi == Approx(b.earliest.contact.toi).margin(kTol));
    for (const Contact& c : b.contacts) {
      if (c.toi > b.earliest.contact.toi + kTol) continue;
      CAPTURE(describe(c));
      const bool found = std::any_of(r.contacts.begin(), r.contacts.end(),
                                     [&](const Contact& x) { return same_feature(x, c); });
      CHECK(found);
      if (rep.contact_frames == 1) rep.first_contacts.push_back(c);
      if (found && in_culled_pair(rvbc, scene, c)) ++rep.wedge_contacts;
    }
    if (stop_at_first_contact) break;
  }
  return rep;
}

}  // namespace tetseg::test
