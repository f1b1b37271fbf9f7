// The two-lane (SIMD) arithmetic of the elementary CCD tests (runtime/src/lanes2.hpp): the
// interval kernels of every check (cross_sums, trilinear, quadrilinear in ccd_forms.hpp, two
// independent products per instruction) and the whole step's coplanarity cubic of two queries
// at once (orientation_detail::cubic2, the batch API) must be bitwise the scalar arithmetic:
// the same intervals, so the same contacts and times of impact. Checked against scalar
// references written here from the scalar operations (Iv, orientation_detail::cubic), on
// random and adversarial values; then the batch API against the calls one by one on a million
// queries, and against the exact rational oracle.

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "../../runtime/src/ccd_forms.hpp"
#include "../../runtime/src/orientation_terms.hpp"
#include "runtime/support/degenerate_queries.hpp"
#include "tetseg/runtime/ccd.hpp"

namespace {

using tetseg::ccd_detail::CrossSums;
using tetseg::ccd_detail::Iv;
using tetseg::ccd_detail::Slot;
using tetseg::ccd_detail::Sums;
using tetseg::ccd_detail::Vec;

/// Bitwise equal, or both NaN (a NaN's payload may depend on the operand order the compiler
/// picked; every NaN decides nothing alike).
bool same(double a, double b) {
  if (std::isnan(a) && std::isnan(b)) return true;
  return std::memcmp(&a, &b, sizeof a) == 0;
}
bool same(const Iv& a, const Iv& b) {
  return same(a.m, b.m) && same(a.r, b.r);
}
bool same(const Vec<Iv>& a, const Vec<Iv>& b) {
  return same(a.x, b.x) && same(a.y, b.y) && same(a.z, b.z);
}
template <int N>
bool same(const Sums<Iv, N>& a, const Sums<Iv, N>& b) {
  for (int k = 0; k <= N; ++k)
    if (!same(a.s[k], b.s[k])) return false;
  return true;
}

// Scalar references: the formulas of ccd_forms.hpp's generic (non-lane) branches, with the
// scalar Iv operations.
Vec<Iv> cross_ref(const Vec<Iv>& a, const Vec<Iv>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Iv dot_ref(const Vec<Iv>& a, const Vec<Iv>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
CrossSums<Iv> cross_sums_ref(const Slot<Iv>& w1, const Slot<Iv>& w2) {
  const Vec<Iv> m0 = cross_ref(w1.v[0], w2.v[1]), m1 = cross_ref(w1.v[1], w2.v[0]);
  return {{cross_ref(w1.v[0], w2.v[0]),
           {m0.x + m1.x, m0.y + m1.y, m0.z + m1.z},
           cross_ref(w1.v[1], w2.v[1])}};
}
Sums<Iv, 3> trilinear_ref(const CrossSums<Iv>& n, const Slot<Iv>& w) {
  return {{dot_ref(n.c[0], w.v[0]), dot_ref(n.c[0], w.v[1]) + dot_ref(n.c[1], w.v[0]),
           dot_ref(n.c[1], w.v[1]) + dot_ref(n.c[2], w.v[0]), dot_ref(n.c[2], w.v[1])}};
}
Sums<Iv, 4> quadrilinear_ref(const CrossSums<Iv>& l, const CrossSums<Iv>& r) {
  return {{dot_ref(l.c[0], r.c[0]), dot_ref(l.c[0], r.c[1]) + dot_ref(l.c[1], r.c[0]),
           dot_ref(l.c[0], r.c[2]) + dot_ref(l.c[1], r.c[1]) + dot_ref(l.c[2], r.c[0]),
           dot_ref(l.c[1], r.c[2]) + dot_ref(l.c[2], r.c[1]), dot_ref(l.c[2], r.c[2])}};
}

/// Adversarial doubles: every magnitude from subnormal to near overflow, exact zeros of both
/// signs, values equal to others (exact cancellation), and now and then inf or NaN.
struct Values {
  std::mt19937_64 rng{20261128};
  std::uniform_real_distribution<double> unit{-1.0, 1.0};
  std::uniform_int_distribution<int> kind{0, 99};
  std::uniform_int_distribution<int> exponent{-1070, 1000};
  double last = 1.0;
  double next() {
    const int k = kind(rng);
    double x;
    if (k < 40)
      x = unit(rng);
    else if (k < 60)
      x = std::ldexp(unit(rng), exponent(rng) / 8);
    else if (k < 70)
      x = std::ldexp(unit(rng), exponent(rng));
    else if (k < 78)
      x = k % 2 == 0 ? 0.0 : -0.0;
    else if (k < 90)
      x = last;  // cancellations
    else if (k < 95)
      x = 1e6 + unit(rng);  // offset far from the origin
    else if (k < 97)
      x = k % 2 == 0 ? std::numeric_limits<double>::infinity() : -1e308;
    else if (k < 98)
      x = std::numeric_limits<double>::quiet_NaN();
    else
      x = std::numeric_limits<double>::denorm_min() * (1 + kind(rng));
    last = x;
    return x;
  }
  Iv interval() {
    const double m = next();
    const int k = kind(rng);
    const double r = k < 50 ? 0.0 : k < 90 ? std::fabs(m) * std::ldexp(1.0, -52 + k % 8) : 0x1p-500;
    return {m, r};
  }
  Vec<Iv> vec() { return {interval(), interval(), interval()}; }
  Slot<Iv> slot() { return {{vec(), vec()}}; }
};

}  // namespace

TEST_CASE("The two-lane interval kernels are bitwise the scalar interval arithmetic",
          "[ccd][lanes]") {
  Values values;
  int differ_cross = 0, differ_tri = 0, differ_quad = 0;
  for (int trial = 0; trial < 1000000; ++trial) {
    const Slot<Iv> w1 = values.slot(), w2 = values.slot(), w3 = values.slot(), w4 = values.slot();
    const CrossSums<Iv> l = tetseg::ccd_detail::cross_sums(w1, w2);
    const CrossSums<Iv> r = tetseg::ccd_detail::cross_sums(w3, w4);
    const CrossSums<Iv> l_ref = cross_sums_ref(w1, w2);
    for (int k = 0; k < 3; ++k) differ_cross += !same(l.c[k], l_ref.c[k]);
    differ_tri += !same(tetseg::ccd_detail::trilinear(l, w3), trilinear_ref(l_ref, w3));
    differ_quad += !same(tetseg::ccd_detail::quadrilinear(l, r), quadrilinear_ref(l_ref, r));
  }
  CHECK(differ_cross == 0);
  CHECK(differ_tri == 0);
  CHECK(differ_quad == 0);
}

TEST_CASE("The leaf enclosures two at a time are bitwise the scalar ones", "[ccd][lanes]") {
  // difference_over2, cross2 and dot2 (ccd_forms.hpp: LeafConditions of a crossing's leaf).
  Values values;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int differ = 0;
  for (int trial = 0; trial < 1000000; ++trial) {
    tetseg::Vec3d p[8];
    for (auto& q : p)
      for (double& c : q) c = values.next();
    const double ta = std::ldexp(std::floor(unit(values.rng) * 1024.0), -10);
    const Iv t = tetseg::ccd_detail::hull(Iv{ta, 0.0}, Iv{ta + 0x1p-30, 0.0});
    Vec<Iv> a, b;
    tetseg::ccd_detail::difference_over2(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], t, a, b);
    differ += !same(a, tetseg::ccd_detail::difference_over(p[0], p[1], p[2], p[3], t));
    differ += !same(b, tetseg::ccd_detail::difference_over(p[4], p[5], p[6], p[7], t));
    const Vec<Iv> u = values.vec(), v = values.vec(), w = values.vec(), x = values.vec();
    Vec<Iv> uv, wx;
    tetseg::ccd_detail::cross2(u, v, w, x, uv, wx);
    differ += !same(uv, cross_ref(u, v)) + !same(wx, cross_ref(w, x));
    Iv d_uv, d_wx;
    tetseg::ccd_detail::dot2(u, v, w, x, d_uv, d_wx);
    differ += !same(d_uv, dot_ref(u, v)) + !same(d_wx, dot_ref(w, x));
  }
  CHECK(differ == 0);
}

TEST_CASE("Two coplanarity cubics at once are bitwise the scalar cubic", "[ccd][lanes]") {
  Values values;
  std::uniform_int_distribution<int> pick(0, 7);
  int differ = 0;
  for (int trial = 0; trial < 1000000; ++trial) {
    std::array<std::array<double, 3>, 16> p;
    for (auto& q : p)
      for (double& c : q) c = values.next();
    // Shared points and shared coordinates (coplanar and degenerate configurations).
    if (trial % 3 == 0) p[pick(values.rng)] = p[pick(values.rng)];
    if (trial % 5 == 0)
      for (auto& q : p) q[2] = p[0][2];
    const double* const points[2][8] = {{p[0].data(), p[1].data(), p[2].data(), p[3].data(),
                                         p[4].data(), p[5].data(), p[6].data(), p[7].data()},
                                        {p[8].data(), p[9].data(), p[10].data(), p[11].data(),
                                         p[12].data(), p[13].data(), p[14].data(), p[15].data()}};
    tetseg::BernsteinCubic two[2];
    tetseg::orientation_detail::cubic2(points, two);
    for (int i = 0; i < 2; ++i) {
      const auto* q = points[i];
      const tetseg::BernsteinCubic one =
          tetseg::orientation_detail::cubic(q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7]);
      for (int k = 0; k < 4; ++k)
        differ += !same(one.k[k], two[i].k[k]) || !same(one.err[k], two[i].err[k]);
    }
  }
  CHECK(differ == 0);
}

namespace {

tetseg::CcdQuery as_query(const tetseg::test::Query& q) {
  tetseg::CcdQuery b;
  for (int i = 0; i < 4; ++i) {
    b.x0[i] = q.x[i];
    b.x1[i] = q.x[4 + i];
  }
  return b;
}

bool same(const tetseg::CcdResult& a, const tetseg::CcdResult& b) {
  return a.outcome == b.outcome && same(a.toi, b.toi) && a.intervals == b.intervals;
}

}  // namespace

TEST_CASE("A batch of elementary tests gives bitwise the results of the calls one by one",
          "[ccd][lanes]") {
  // The degenerate families of simulator steps (ending, sliding, starting in an axis plane,
  // nearly in it, on a grid, partly still, generic crossings), scaled by 1e-4 .. 1e4 and offset
  // by 1e6, vertex-face and edge-edge, in batches of odd and even sizes; with exact contact
  // (the two-lane cubic) and with a minimum separation (no lanes).
  std::mt19937_64 rng(25);
  using tetseg::test::Family;
  int differ = 0, hits = 0, total = 0;
  std::vector<tetseg::test::Query> queries;
  std::vector<tetseg::CcdQuery> batch;
  std::vector<tetseg::CcdResult> results;
  for (int round = 0; round < 4000; ++round) {
    const bool edge_edge = round % 2 == 1;
    const std::size_t size = 1 + round % 500;
    tetseg::CcdOptions options;
    if (round % 10 == 9) options.min_separation = 1e-3;
    queries.clear();
    batch.clear();
    for (std::size_t i = 0; i < size; ++i) {
      const auto family = static_cast<Family>((round + i) % tetseg::test::kFamilies);
      queries.push_back(tetseg::test::make_query(rng, family, edge_edge));
      batch.push_back(as_query(queries.back()));
    }
    results.assign(size, tetseg::CcdResult{});
    if (edge_edge)
      tetseg::edge_edge_ccd_batch(batch.data(), size, results.data(), options);
    else
      tetseg::vertex_face_ccd_batch(batch.data(), size, results.data(), options);
    for (std::size_t i = 0; i < size; ++i) {
      const auto& x = queries[i].x;
      const tetseg::CcdResult one =
          edge_edge
              ? tetseg::edge_edge_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], options)
              : tetseg::vertex_face_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], options);
      differ += !same(one, results[i]);
      hits += one.hit();
      ++total;
    }
  }
  INFO(total << " queries, " << hits << " contacts");
  CHECK(total > 1000000);
  CHECK(hits > total / 10);  // not only non-contacts
  CHECK(differ == 0);
}

TEST_CASE("A batch of elementary tests misses no exact contact and is never late",
          "[ccd][lanes][exact]") {
  std::mt19937_64 rng(2026);
  int missed = 0, late = 0, start_wrong = 0, hits = 0;
  for (int round = 0; round < 140; ++round) {
    const bool edge_edge = round % 2 == 1;
    std::vector<tetseg::test::Query> queries;
    std::vector<tetseg::CcdQuery> batch;
    for (int i = 0; i < 100; ++i) {
      const auto family = static_cast<tetseg::test::Family>(i % tetseg::test::kFamilies);
      queries.push_back(tetseg::test::make_query(rng, family, edge_edge));
      batch.push_back(as_query(queries.back()));
    }
    std::vector<tetseg::CcdResult> results(batch.size());
    if (edge_edge)
      tetseg::edge_edge_ccd_batch(batch.data(), batch.size(), results.data());
    else
      tetseg::vertex_face_ccd_batch(batch.data(), batch.size(), results.data());
    for (std::size_t i = 0; i < batch.size(); ++i) {
      const tetseg::test::ExactCcd e = tetseg::test::exact_result(queries[i]);
      const tetseg::CcdResult& r = results[i];
      hits += e.hit;
      if (e.hit && !r.hit()) ++missed;
      if (e.hit && r.hit() && r.toi > e.toi_upper) ++late;
      if (e.at_start && r.outcome != tetseg::CcdOutcome::kContactAtStart) ++start_wrong;
    }
  }
  INFO(hits << " exact contacts in 14,000 queries");
  CHECK(hits > 1000);
  CHECK(missed == 0);
  CHECK(late == 0);
  CHECK(start_wrong == 0);
}
