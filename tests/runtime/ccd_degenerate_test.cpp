// The elementary CCD tests on the degenerate contacts of simulator steps, against the exact
// rational oracle (testing/include/tetseg/testing/exact_ccd.hpp): four points ending in one
// axis-aligned plane (a body flattened onto the ground), sliding in such a plane for the whole
// step, starting in it, nearly in it at the end, on a coarse grid (exact touching, collinear
// and coincident features), ordinary crossings, and still features; scaled by 1e-4 .. 1e4 and
// offset by 1e6. No exact contact may be missed, no time of impact may come after the exact
// one, contact at t = 0 must be reported as such, and where the answer is not within rounding
// of a degeneracy no false positive is allowed. The positive certificates (docs/ccd.md) must
// also decide the common cases without bisecting (work counts, not timings).

#include <array>
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "runtime/support/degenerate_queries.hpp"
#include "tetseg/runtime/ccd.hpp"
#include "tetseg/testing/exact_ccd.hpp"

namespace {

using tetseg::CcdOutcome;
using tetseg::CcdResult;
using tetseg::Vec3d;
using namespace tetseg::test;

}  // namespace

TEST_CASE("Degenerate simulator contacts: none missed, none late, no false positive off rounding",
          "[ccd][exact]") {
  std::mt19937_64 rng(20261128);
  struct Counts {
    int queries = 0, hits = 0, missed = 0, late = 0, start_wrong = 0, false_positives = 0;
    int end_contacts = 0, end_contacts_decided_at_once = 0;
    int crossings = 0, crossings_decided_quickly = 0;
    int generic_decided_at_leaf = 0;
  } counts[kFamilies];
  for (int i = 0; i < 28000; ++i) {
    const Family family = static_cast<Family>((i / 2) % kFamilies);
    const Query q = make_query(rng, family, i % 2 == 1);
    const CcdResult r = run(q);
    const tetseg::test::ExactCcd e = exact_result(q);
    Counts& c = counts[family];
    ++c.queries;
    c.hits += e.hit;
    if (e.hit && !r.hit()) ++c.missed;
    if (e.hit && r.hit() && r.toi > e.toi_upper) ++c.late;
    if (e.at_start && r.outcome != CcdOutcome::kContactAtStart) ++c.start_wrong;
    if (!e.hit && r.hit()) ++c.false_positives;
    if (family == kEndInPlane && e.hit && e.toi_lower == 1.0) {
      ++c.end_contacts;
      if (r.intervals <= 2) ++c.end_contacts_decided_at_once;
    }
    // A generic crossing inside the step: the cubic's root leaf is reached at once (no
    // halving down to it), and the time of impact lands within the tolerance before the root.
    if (family == kGenericCrossing && e.hit && e.toi_lower > 0.0 && e.toi_upper < 1.0) {
      ++c.crossings;
      if (r.intervals <= 10 && r.toi >= e.toi_lower - 2e-9) ++c.crossings_decided_quickly;
    }
    // Generic motion, hit or miss: the whole step's cubic in doubles, then at most the leaf of
    // its crossing, decided by the enclosures of the inside conditions (docs/ccd.md, "Exact
    // contacts at the speed of float", item 7): two intervals at most, a contact within one
    // leaf (the tolerance, 1e-9) before the exact time.
    if (family == kGenericCrossing && r.intervals <= 2 && (!r.hit() || r.toi >= e.toi_lower - 1e-9))
      ++c.generic_decided_at_leaf;
  }
  for (int f = 0; f < kFamilies; ++f) {
    const Counts& c = counts[f];
    INFO(kFamilyNames[f] << ": " << c.queries << " queries, " << c.hits << " exact contacts, "
                         << c.missed << " missed, " << c.late << " late, " << c.false_positives
                         << " false positives");
    CHECK(c.hits > c.queries / 20);  // every family has contacts to find
    CHECK(c.missed == 0);
    CHECK(c.late == 0);
    CHECK(c.start_wrong == 0);
    // Off the grid (exact touching, where double-double leaves may stay undecided), no false
    // positive: in particular none while sliding in a plane, where the triangle degenerating
    // to a segment made every edge-plane condition vanish (the 2D orientations decide).
    if (f != kGrid) CHECK(c.false_positives == 0);
  }
  // Touching at t = 1 in the plane: the end certificate decides almost all without bisecting.
  const Counts& end = counts[kEndInPlane];
  INFO(end.end_contacts_decided_at_once << " of " << end.end_contacts
                                        << " contacts at t = 1 decided in at most 2 intervals");
  CHECK(end.end_contacts > 200);
  CHECK(end.end_contacts_decided_at_once >= end.end_contacts * 9 / 10);
  // Crossings inside the step: the jump to the root leaf (about 48 intervals when halving).
  const Counts& generic = counts[kGenericCrossing];
  INFO(generic.crossings_decided_quickly << " of " << generic.crossings
                                         << " crossings decided in at most 10 intervals");
  CHECK(generic.crossings > 200);
  CHECK(generic.crossings_decided_quickly >= generic.crossings * 9 / 10);
  INFO(generic.generic_decided_at_leaf << " of " << generic.queries
                                       << " generic queries decided in at most 2 intervals");
  CHECK(generic.generic_decided_at_leaf >= generic.queries * 9 / 10);
}

TEST_CASE("Contacts in an axis plane are certified at their exact times", "[ccd]") {
  // Vertex p lands inside triangle abc on the ground z = 0 at t = 1, from above.
  const Vec3d a0{0, 0, 0.5}, b0{1, 0, 0.25}, c0{0, 1, 0.5}, p0{0.25, 0.25, 1};
  const Vec3d a1{0, 0, 0}, b1{1, 0, 0}, c1{0, 1, 0}, p1{0.25, 0.25, 0};
  const CcdResult land = tetseg::vertex_face_ccd(p0, a0, b0, c0, p1, a1, b1, c1);
  CHECK(land.outcome == CcdOutcome::kContact);
  CHECK(land.toi <= 1.0);
  CHECK(land.toi >= 1.0 - 1e-9);
  CHECK(land.intervals <= 2);  // decided by the end certificate, no bisection

  // Sliding on the ground: p enters the triangle through edge ca (x = 0) at t = 0.5 exactly.
  const Vec3d q0{-0.25, 0.25, 0}, q1{0.25, 0.25, 0};
  const CcdResult slide = tetseg::vertex_face_ccd(q0, a1, b1, c1, q1, a1, b1, c1);
  CHECK(slide.outcome == CcdOutcome::kContact);
  CHECK(slide.toi <= 0.5);
  CHECK(slide.toi >= 0.5 - 1e-9);

  // Two edges crossing on the ground at the start: contact at start, no interval examined
  // beyond the certificate.
  const Vec3d e0{0, 0, 0}, e1{1, 1, 0}, f0{0, 1, 0}, f1{1, 0, 0};
  const CcdResult start = tetseg::edge_edge_ccd(e0, e1, f0, f1, e0, e1, f0, f1);
  CHECK(start.outcome == CcdOutcome::kContactAtStart);
  CHECK(start.toi == 0.0);
  CHECK(start.intervals == 1);

  // Two edges landing on the ground apart (parallel, one unit between them): the end
  // certificate proves the miss without bisecting.
  const Vec3d s0{0, 0, 1}, s1{1, 0, 0.5}, r0{0, 1, 1}, r1{1, 1, 0.5};
  const Vec3d s0_end{0, 0, 0}, s1_end{1, 0, 0}, r0_end{0, 1, 0}, r1_end{1, 1, 0};
  const CcdResult apart = tetseg::edge_edge_ccd(s0, s1, r0, r1, s0_end, s1_end, r0_end, r1_end);
  CHECK(!apart.hit());
  CHECK(apart.intervals == 1);

  // The same edges lifted apart by one ulp of height at the start: no certificate applies
  // (not in one plane), and they never touch while one stays above the other.
  const Vec3d g0{0, 1, 0x1p-52}, g1{1, 0, 0x1p-52};
  CHECK(!tetseg::edge_edge_ccd(e0, e1, g0, g1, e0, e1, g0, g1).hit());
}

TEST_CASE("Collinear edges sliding along their line: apart is a miss and touching a hit",
          "[ccd][exact]") {
  // Four points on one line through the origin (a direction with no zero coordinate: never
  // in one axis plane, so no plane certificate applies), at integer multiples of it. The
  // common normal of the edges vanishes, so only the end caps (both points of one edge beyond
  // an endpoint of the other) prove a miss on the whole step: the points move 8 units along
  // the line, so the swept boxes overlap and without the caps the miss takes a bisection down
  // to intervals short enough for the boxes. Against the exact oracle.
  std::mt19937_64 rng(25);
  std::uniform_int_distribution<int> coord(1, 5), length(1, 4), shift(-3, 3), gap(1, 3);
  int misses = 0, touches = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3d dir{double(coord(rng)), -double(coord(rng)), double(coord(rng))};
    auto at = [&](double s) { return Vec3d{s * dir[0], s * dir[1], s * dir[2]}; };
    // Edge ab, then edge cd after a gap, at both ends of the step; with `touch`, c ends on b.
    const bool touch = i % 2 == 1;
    double s0[4], s1[4];
    for (double* s : {s0, s1}) {
      s[0] = shift(rng);
      s[1] = s[0] + length(rng);
      s[2] = s[1] + gap(rng);
      s[3] = s[2] + length(rng);
    }
    for (double& s : s1) s += 8;
    if (touch) {
      s1[3] += s1[1] - s1[2];
      s1[2] = s1[1];
    }
    const Query q{
        true,
        kGrid,
        {at(s0[0]), at(s0[1]), at(s0[2]), at(s0[3]), at(s1[0]), at(s1[1]), at(s1[2]), at(s1[3])}};
    const CcdResult r = run(q);
    const tetseg::test::ExactCcd e = exact_result(q);
    INFO("query " << i << ": line (" << dir[0] << ", " << dir[1] << ", " << dir[2] << ")");
    REQUIRE(e.hit == touch);
    CHECK(r.hit() == touch);
    if (touch) CHECK(r.toi <= e.toi_upper);
    if (!touch) CHECK(r.intervals == 1);  // the caps exclude the whole step at once
    misses += !r.hit();
    touches += r.hit();
  }
  CHECK(misses == 200);
  CHECK(touches == 200);
}
