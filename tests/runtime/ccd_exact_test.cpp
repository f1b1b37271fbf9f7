// The exact rational CCD oracle (testing/include/tetseg/testing/exact_ccd.hpp) against
// independent truth: analytic times of impact, the exact ground truth of the public reference
// queries, and exact point-triangle / segment-segment distances at rational sample times
// (closest-point formulas, no shared code with the oracle's polynomial conditions).

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "tetseg/runtime/ccd.hpp"
#include "tetseg/testing/ccd_io.hpp"
#include "tetseg/testing/exact_ccd.hpp"
#include "tetseg/testing/test_data.hpp"

using tetseg::Vec3d;
using tetseg::test::exact_edge_edge;
using tetseg::test::exact_vertex_face;
using tetseg::test::ExactCcd;

namespace {

namespace fs = std::filesystem;
namespace io = tetseg::test::ccd_io;

using Q3 = std::array<mpq_class, 3>;

Q3 at(const Vec3d& x0, const Vec3d& x1, const mpq_class& t) {
  Q3 r;
  for (int k = 0; k < 3; ++k) r[k] = mpq_class(x0[k]) + t * (mpq_class(x1[k]) - mpq_class(x0[k]));
  return r;
}
Q3 sub(const Q3& a, const Q3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Q3 axpy(const Q3& a, const mpq_class& s, const Q3& d) {
  return {a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]};
}
mpq_class dot(const Q3& a, const Q3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Squared distance from x to the closed segment [y, z] (clamped projection).
mpq_class point_segment_sq(const Q3& x, const Q3& y, const Q3& z) {
  const Q3 e = sub(z, y), v = sub(x, y);
  const mpq_class ee = dot(e, e);
  if (ee == 0) return dot(v, v);
  mpq_class s = dot(v, e) / ee;
  s = std::max(mpq_class(0), std::min(mpq_class(1), s));
  const Q3 r = sub(x, axpy(y, s, e));
  return dot(r, r);
}

/// Squared distance from p to the closed triangle (a, b, c): the plane projection when it falls
/// inside a non-degenerate triangle (Gram system), otherwise the nearest edge.
mpq_class point_triangle_sq(const Q3& p, const Q3& a, const Q3& b, const Q3& c) {
  mpq_class best =
      std::min({point_segment_sq(p, a, b), point_segment_sq(p, b, c), point_segment_sq(p, c, a)});
  const Q3 e1 = sub(b, a), e2 = sub(c, a), v = sub(p, a);
  const mpq_class g11 = dot(e1, e1), g12 = dot(e1, e2), g22 = dot(e2, e2);
  const mpq_class det = g11 * g22 - g12 * g12;
  if (det != 0) {
    const mpq_class r1 = dot(v, e1), r2 = dot(v, e2);
    const mpq_class s = (r1 * g22 - r2 * g12) / det, u = (r2 * g11 - r1 * g12) / det;
    if (s >= 0 && u >= 0 && s + u <= 1) {
      const Q3 r = sub(p, axpy(axpy(a, s, e1), u, e2));
      best = std::min(best, dot(r, r));
    }
  }
  return best;
}

/// Squared distance between the closed segments [a, b] and [c, d]: the interior critical point
/// of the non-parallel lines when inside both, else an endpoint against the other segment.
mpq_class segment_segment_sq(const Q3& a, const Q3& b, const Q3& c, const Q3& d) {
  mpq_class best = std::min({point_segment_sq(a, c, d), point_segment_sq(b, c, d),
                             point_segment_sq(c, a, b), point_segment_sq(d, a, b)});
  const Q3 e1 = sub(b, a), e2 = sub(d, c), w = sub(a, c);
  const mpq_class A = dot(e1, e1), B = dot(e1, e2), C = dot(e2, e2), D = dot(e1, w), E = dot(e2, w);
  const mpq_class den = A * C - B * B;
  if (den != 0) {
    const mpq_class s = (B * E - C * D) / den, u = (A * E - B * D) / den;
    if (s >= 0 && s <= 1 && u >= 0 && u <= 1) {
      const Q3 r = sub(axpy(a, s, e1), axpy(c, u, e2));
      best = std::min(best, dot(r, r));
    }
  }
  return best;
}

using Query = std::array<Vec3d, 8>;

mpq_class distance_sq_at(const Query& x, bool vertex_face, const mpq_class& t) {
  const Q3 p = at(x[0], x[4], t), a = at(x[1], x[5], t), b = at(x[2], x[6], t),
           c = at(x[3], x[7], t);
  return vertex_face ? point_triangle_sq(p, a, b, c) : segment_segment_sq(p, a, b, c);
}

ExactCcd oracle(const Query& x, bool vertex_face) {
  return vertex_face ? exact_vertex_face(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7])
                     : exact_edge_edge(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
}

/// An upper bound of how fast the distance can change per unit t: the sum of the largest
/// displacement on each side (distances between moving sets are Lipschitz in it).
mpq_class speed_bound(const Query& x, bool vertex_face) {
  auto disp = [&](int i) {
    const Q3 d = sub(at(x[i], x[i + 4], 1), at(x[i], x[i + 4], 0));
    return dot(d, d);
  };
  // |d| <= 1 + |d|^2 keeps it rational.
  const int split = vertex_face ? 1 : 2;
  mpq_class s1 = 0, s2 = 0;
  for (int i = 0; i < 4; ++i) (i < split ? s1 : s2) = std::max(i < split ? s1 : s2, disp(i));
  return 2 + s1 + s2;
}

/// Checks the oracle's answer against the exact distance: zero at every reported first contact
/// (within the speed bound over the enclosure), positive at every sample before it, and for a
/// miss positive at every sample. Returns the number of samples that touched.
int check_against_distance(const Query& x, bool vertex_face, const ExactCcd& r, int samples) {
  int touching = 0;
  if (r.hit) {
    CHECK(r.toi_lower <= r.toi_upper);
    CHECK((r.toi_upper == r.toi_lower || r.toi_upper == std::nextafter(r.toi_lower, 2.0)));
    CHECK(r.toi_lower >= 0.0);
    CHECK(r.toi_upper <= 1.0);
    const mpq_class width = mpq_class(r.toi_upper) - mpq_class(r.toi_lower);
    const mpq_class v = speed_bound(x, vertex_face);
    CHECK(distance_sq_at(x, vertex_face, mpq_class(r.toi_upper)) <= v * v * width * width);
    CHECK(r.at_start == (distance_sq_at(x, vertex_face, 0) == 0));
  } else {
    CHECK_FALSE(distance_sq_at(x, vertex_face, 0) == 0);
  }
  for (int k = 0; k <= samples; ++k) {
    const mpq_class t(k, samples);
    const bool touches = distance_sq_at(x, vertex_face, t) == 0;
    touching += touches;
    if (touches) {
      CAPTURE(k, samples);
      REQUIRE(r.hit);
      REQUIRE(mpq_class(r.toi_lower) <= t);
    }
  }
  return touching;
}

Vec3d v(double x, double y, double z) {
  return {x, y, z};
}

}  // namespace

TEST_CASE("The exact CCD oracle finds analytic contacts and misses", "[ccd][exact]") {
  const Vec3d a = v(0, 0, 0), b = v(1, 0, 0), c = v(0, 1, 0);
  SECTION("A vertex falling through a triangle meets it at the analytic time.") {
    const ExactCcd r = exact_vertex_face(v(0.25, 0.25, 1), a, b, c, v(0.25, 0.25, -3), a, b, c);
    CHECK(r.hit);
    CHECK_FALSE(r.at_start);
    CHECK(r.toi_upper == 0.25);
    CHECK(r.toi_lower == 0.25);
    const ExactCcd third = exact_vertex_face(v(0.25, 0.25, 1), a, b, c, v(0.25, 0.25, -2), a, b, c);
    CHECK(third.toi_lower < 1.0 / 3.0 + 1e-16);
    CHECK(third.toi_upper > 1.0 / 3.0 - 1e-16);
    CHECK(third.toi_upper == std::nextafter(third.toi_lower, 1.0));
  }
  SECTION("Passing beside the triangle, or stopping short of it, misses.") {
    CHECK_FALSE(exact_vertex_face(v(0.6, 0.6, 1), a, b, c, v(0.6, 0.6, -1), a, b, c).hit);
    CHECK_FALSE(exact_vertex_face(v(0.2, 0.2, 1), a, b, c, v(0.2, 0.2, 1e-300), a, b, c).hit);
  }
  SECTION("Touching at the ends of the step.") {
    const ExactCcd start = exact_vertex_face(v(0.5, 0.5, 0), a, b, c, v(0.5, 0.5, 1), a, b, c);
    CHECK(start.hit);
    CHECK(start.at_start);  // on the hypotenuse at t = 0
    CHECK(start.toi_upper == 0.0);
    const ExactCcd end = exact_vertex_face(v(0, 0, 1), a, b, c, v(0, 0, 0), a, b, c);
    CHECK(end.hit);
    CHECK_FALSE(end.at_start);
    CHECK(end.toi_upper == 1.0);
  }
  SECTION("Sliding in the plane of the triangle reaches its edge at the analytic time.") {
    const ExactCcd r = exact_vertex_face(v(-1, 0.5, 0), a, b, c, v(1, 0.5, 0), a, b, c);
    CHECK(r.hit);
    CHECK(r.toi_upper == 0.5);
    CHECK_FALSE(exact_vertex_face(v(-1, 1.5, 0), a, b, c, v(1, 1.5, 0), a, b, c).hit);
  }
  SECTION("A triangle collapsing to a segment, and zero-area triangles.") {
    // c falls onto the segment ab at t = 1; the vertex sits on ab's middle only then.
    const ExactCcd r = exact_vertex_face(v(0.5, 0, 1), a, b, c, v(0.5, 0, 0), a, b, v(0.5, 0, 0));
    CHECK(r.hit);
    CHECK(r.toi_upper == 1.0);
    // A segment-shaped triangle swept across a vertex: contact when the segment passes it.
    const ExactCcd seg = exact_vertex_face(v(0.5, 0.5, 0), v(0, 0, 0), v(1, 1, 0), v(2, 2, 0),
                                           v(0.5, 0.5, 0), v(0, 1, 0), v(1, 2, 0), v(2, 3, 0));
    CHECK(seg.at_start);  // the line y = x + t holds (0.5, 0.5) at t = 0 only ...
    const ExactCcd seg2 = exact_vertex_face(v(0.5, 0.75, 0), v(0, 0, 0), v(1, 1, 0), v(2, 2, 0),
                                            v(0.5, 0.75, 0), v(0, 1, 0), v(1, 2, 0), v(2, 3, 0));
    CHECK(seg2.hit);  // ... and holds (0.5, 0.75) at t = 1/4
    CHECK(seg2.toi_upper == 0.25);
    // A triangle that is a single point, and a vertex reaching it.
    const ExactCcd point = exact_vertex_face(v(0, 0, 0), b, b, b, v(2, 0, 0), b, b, b);
    CHECK(point.hit);
    CHECK(point.toi_upper == 0.5);
  }
  SECTION("Zero motion: touching throughout, or never.") {
    const ExactCcd still = exact_vertex_face(v(0.1, 0.1, 0), a, b, c, v(0.1, 0.1, 0), a, b, c);
    CHECK(still.at_start);
    CHECK_FALSE(exact_vertex_face(v(0.1, 0.1, 1e-300), a, b, c, v(0.1, 0.1, 1e-300), a, b, c).hit);
  }
  SECTION("Edges crossing, sliding along each other, parallel and degenerate.") {
    const ExactCcd cross = exact_edge_edge(v(0, 0, 1), v(1, 0, 1), v(0.5, -1, 0), v(0.5, 1, 0),
                                           v(0, 0, -1), v(1, 0, -1), v(0.5, -1, 0), v(0.5, 1, 0));
    CHECK(cross.hit);
    CHECK(cross.toi_upper == 0.5);
    const ExactCcd miss = exact_edge_edge(v(0, 0, 1), v(1, 0, 1), v(1.5, -1, 0), v(1.5, 1, 0),
                                          v(0, 0, -1), v(1, 0, -1), v(1.5, -1, 0), v(1.5, 1, 0));
    CHECK_FALSE(miss.hit);
    // Collinear edges sliding towards each other: the ends meet at t = 3/4.
    const ExactCcd collinear = exact_edge_edge(v(0, 0, 0), v(1, 0, 0), v(4, 0, 0), v(5, 0, 0),
                                               v(0, 0, 0), v(1, 0, 0), v(0, 0, 0), v(1, 0, 0));
    CHECK(collinear.hit);
    CHECK(collinear.toi_upper == 0.75);
    // Parallel, one unit apart in the plane: never.
    CHECK_FALSE(exact_edge_edge(v(0, 0, 0), v(1, 0, 0), v(4, 1, 0), v(5, 1, 0), v(0, 0, 0),
                                v(1, 0, 0), v(0, 1, 0), v(1, 1, 0))
                    .hit);
    // A zero-length edge (a point) passing through a segment at t = 1/2.
    const ExactCcd point = exact_edge_edge(v(0.5, 0, 1), v(0.5, 0, 1), v(0, 0, 0), v(1, 0, 0),
                                           v(0.5, 0, -1), v(0.5, 0, -1), v(0, 0, 0), v(1, 0, 0));
    CHECK(point.hit);
    CHECK(point.toi_upper == 0.5);
    // Two zero-length edges at different places, still: never.
    CHECK_FALSE(exact_edge_edge(a, a, b, b, a, a, b, b).hit);
    CHECK(exact_edge_edge(a, a, a, a, a, a, a, a).at_start);
  }
  SECTION("A time of impact that is no double is enclosed by its two neighbours.") {
    // c(t) = (0, 1, 4t - 1): the plane through a, b, c is z = y (4t - 1); p(t) = (1/8, 1/8,
    // 1 - 2t) lies in it when 1 - 2t = (4t - 1) / 8, at t = 9/20.
    const Query x = {v(0.125, 0.125, 1), a, b, v(0, 1, -1), v(0.125, 0.125, -1), a, b, v(0, 1, 3)};
    const ExactCcd r = oracle(x, true);
    CHECK(r.hit);
    CHECK(r.toi_upper == std::nextafter(r.toi_lower, 1.0));
    CHECK(mpq_class(r.toi_lower) < mpq_class(9, 20));
    CHECK(mpq_class(r.toi_upper) > mpq_class(9, 20));
    check_against_distance(x, true, r, 64);
  }
}

namespace {

const fs::path kQueries = fs::path(TETSEG_SHARED_DIR) / "data/ccd-queries/sample-queries";

}  // namespace

TEST_CASE("The exact CCD oracle agrees with every reference query's exact truth",
          "[ccd][exact][reference]") {
  if (!tetseg::test::have_test_data(kQueries.string(), "CCD reference queries")) return;
  long queries = 0, positives = 0, disagreements = 0;
  for (const char* kind : {"vertex-face", "edge-edge"}) {
    const bool vertex_face = kind[0] == 'v';
    std::vector<fs::path> files;
    for (const auto& scene : fs::directory_iterator(kQueries))
      if (fs::is_directory(scene.path() / kind))
        for (const auto& e : fs::directory_iterator(scene.path() / kind))
          if (e.path().extension() == ".csv") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& file : files) {
      for (const auto& q : io::read_query_csv(file.string())) {
        const ExactCcd r = oracle(q.points, vertex_face);
        ++queries;
        positives += q.truth;
        if (r.hit != q.truth) {
          ++disagreements;
          UNSCOPED_INFO("disagreement in " << file.string());
        }
      }
    }
  }
  CHECK(queries == 7279);
  CHECK(positives == 248 + 187);
  CHECK(disagreements == 0);
}

namespace {

/// Random small-integer configurations (many exact coincidences: coplanar, collinear, equal
/// points, still nodes), scaled by a power of two so that every value is exact.
Query grid_query(std::mt19937_64& rng, int range, double scale) {
  std::uniform_int_distribution<int> coord(-range, range), pick(0, 9);
  Query x;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) x[i][k] = scale * coord(rng);
  for (int i = 0; i < 4; ++i) {
    const int kind = pick(rng);
    for (int k = 0; k < 3; ++k) {
      if (kind == 0)
        x[i + 4][k] = x[i][k];  // still
      else if (kind == 1)
        x[i + 4][k] = x[(i + 1) % 4][k];  // moves onto another node's start
      else
        x[i + 4][k] = scale * coord(rng);
    }
  }
  if (pick(rng) < 3)  // everything in the plane z = 0 for the whole step
    for (auto& p : x) p[2] = 0;
  return x;
}

}  // namespace

TEST_CASE("The exact CCD oracle agrees with exact distances on random grid configurations",
          "[ccd][exact][random]") {
  std::mt19937_64 rng(20261128);
  int hits = 0, at_start = 0, touching_samples = 0, trials = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const bool vertex_face = trial % 2 == 0;
    const Query x = grid_query(rng, trial % 3 == 0 ? 1 : 2, trial % 5 == 0 ? 0.125 : 1.0);
    const ExactCcd r = oracle(x, vertex_face);
    CAPTURE(trial, vertex_face);
    touching_samples += check_against_distance(x, vertex_face, r, 24) > 0;
    hits += r.hit;
    at_start += r.at_start;
    ++trials;
  }
  // Not vacuous: contacts of every sort occur.
  CHECK(hits > trials / 10);
  CHECK(at_start > trials / 50);
  CHECK(touching_samples > trials / 20);
  CHECK(hits - touching_samples > trials / 50);  // contacts only between the samples
}

namespace {

struct RuntimeCounts {
  long queries = 0, exact_hits = 0, missed = 0, late = 0, start_missed = 0;
};

/// The runtime's answer against the exact one: every exact contact reported, never after the
/// exact first contact time, and a contact at t = 0 reported as such.
void compare_runtime(const Query& x, bool vertex_face, RuntimeCounts& c) {
  const ExactCcd e = oracle(x, vertex_face);
  const tetseg::CcdResult r =
      vertex_face ? tetseg::vertex_face_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7])
                  : tetseg::edge_edge_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
  ++c.queries;
  if (!e.hit) return;
  ++c.exact_hits;
  if (!r.hit()) {
    ++c.missed;
    return;
  }
  if (r.toi > e.toi_upper) ++c.late;
  if (e.at_start && r.toi != 0.0) ++c.start_missed;
}

}  // namespace

TEST_CASE("The runtime's elementary tests never miss an exact contact nor report it late",
          "[ccd][exact][random]") {
  RuntimeCounts c;
  SECTION("Random grid configurations: coplanar, collinear, still and coinciding nodes.") {
    std::mt19937_64 rng(7);
    for (int trial = 0; trial < 20000; ++trial)
      compare_runtime(grid_query(rng, trial % 3 == 0 ? 1 : 2, trial % 5 == 0 ? 0.125 : 1.0),
                      trial % 2 == 0, c);
    CHECK(c.exact_hits > 2000);
  }
  SECTION("Near-grazing: a node passing within a few ulps of an edge, a corner or a plane.") {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    std::uniform_int_distribution<int> ulps(-4, 4);
    for (int trial = 0; trial < 6000; ++trial) {
      Query x;
      for (auto& p : x)
        for (double& k : p) k = u(rng);
      const bool vertex_face = trial % 2 == 0;
      // At t = s the moving node (0) sits on a point of the other primitive's closed set (an
      // edge point, a corner or an inside point), give or take a few ulps.
      const double s = (trial % 3 == 0) ? 0.0 : (trial % 3 == 1 ? 1.0 : 0.5);
      const double w = (trial % 4 == 0) ? 0.0 : std::abs(u(rng));
      Vec3d target;
      for (int k = 0; k < 3; ++k) {
        const double y = x[2][k] + s * (x[6][k] - x[2][k]);
        const double z = x[3][k] + s * (x[7][k] - x[3][k]);
        target[k] = y + w * (z - y);
        for (int n = ulps(rng); n != 0; n += n > 0 ? -1 : 1)
          target[k] = std::nextafter(target[k], n > 0 ? 2.0 : -2.0);
      }
      // Node 0 passes through the target at t = s: x0 + s (x1 - x0) = target.
      for (int k = 0; k < 3; ++k) {
        if (s == 0.0) x[0][k] = target[k];
        if (s == 1.0) x[4][k] = target[k];
        if (s == 0.5) x[4][k] = 2 * target[k] - x[0][k];
      }
      compare_runtime(x, vertex_face, c);
    }
    CHECK(c.exact_hits > 300);
  }
  SECTION("Every reference query: the runtime's time of impact is never after the exact one.") {
    if (!tetseg::test::have_test_data(kQueries.string(), "CCD reference queries")) return;
    for (const char* kind : {"vertex-face", "edge-edge"})
      for (const auto& scene : fs::directory_iterator(kQueries))
        if (fs::is_directory(scene.path() / kind))
          for (const auto& e : fs::directory_iterator(scene.path() / kind))
            if (e.path().extension() == ".csv")
              for (const auto& q : io::read_query_csv(e.path().string()))
                compare_runtime(q.points, kind[0] == 'v', c);
    CHECK(c.queries == 7279);
    CHECK(c.exact_hits == 435);
  }
  CAPTURE(c.queries, c.exact_hits);
  CHECK(c.missed == 0);
  CHECK(c.late == 0);
  CHECK(c.start_missed == 0);
}
