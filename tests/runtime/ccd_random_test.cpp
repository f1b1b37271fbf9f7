// Randomized cross-check of the elementary CCD tests against dense time sampling with
// Lipschitz margins. Only cases whose answer is clear from the samples are asserted:
//  - clear contact: the coplanarity function changes sign between two samples while the point
//    (the crossing) stays inside with a margin at both; the test must report it, no later
//    than the second sample;
//  - clear miss: the sampled distance stays above the largest change the distance can have
//    between samples (speed bound times step); the test must not report it.
// Ambiguous (near-grazing) cases are skipped and counted.

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "tetseg/runtime/ccd.hpp"
#include "tetseg/testing/point_triangle.hpp"

namespace {

using tetseg::Vec3d;

Vec3d sub(const Vec3d& a, const Vec3d& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3d add(const Vec3d& a, const Vec3d& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
Vec3d mul(const Vec3d& a, double s) {
  return {a[0] * s, a[1] * s, a[2] * s};
}
double dot(const Vec3d& a, const Vec3d& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3d& a) {
  return std::sqrt(dot(a, a));
}
Vec3d lerp(const Vec3d& a, const Vec3d& b, double t) {
  return add(a, mul(sub(b, a), t));
}

double clamp01(double x) {
  return std::min(1.0, std::max(0.0, x));
}

/// Distance between segments p1q1 and p2q2 (Ericson 5.1.9).
double segment_distance(const Vec3d& p1, const Vec3d& q1, const Vec3d& p2, const Vec3d& q2) {
  const Vec3d d1 = sub(q1, p1), d2 = sub(q2, p2), r = sub(p1, p2);
  const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
  double s, t;
  if (a <= 1e-30 && e <= 1e-30) return norm(r);
  if (a <= 1e-30) {
    s = 0;
    t = clamp01(f / e);
  } else {
    const double c = dot(d1, r);
    if (e <= 1e-30) {
      t = 0;
      s = clamp01(-c / a);
    } else {
      const double b = dot(d1, d2), denom = a * e - b * b;
      s = denom > 0 ? clamp01((b * f - c * e) / denom) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = clamp01(-c / a);
      } else if (t > 1) {
        t = 1;
        s = clamp01((b - c) / a);
      }
    }
  }
  return norm(sub(add(p1, mul(d1, s)), add(p2, mul(d2, t))));
}

constexpr int kSamples = 1024;

struct Case {
  std::array<Vec3d, 4> x0, x1;
  double speed = 0;  // Lipschitz bound of the distance in t
  void finish() {
    double p = norm(sub(x1[0], x0[0])), q = norm(sub(x1[1], x0[1]));
    double r = std::max(norm(sub(x1[2], x0[2])), norm(sub(x1[3], x0[3])));
    speed = vertex_face ? p + std::max({q, r}) : std::max(p, q) + r;
  }
  bool vertex_face = true;
};

Vec3d random_vec(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  return {u(rng), u(rng), u(rng)};
}

/// A random triangle and a point that crosses its plane near it (about half hit).
Case random_vertex_face(std::mt19937_64& rng) {
  Case c;
  c.vertex_face = true;
  std::uniform_real_distribution<double> w(-0.4, 1.2), h(0.05, 0.6);
  for (int i = 1; i < 4; ++i) {
    c.x0[static_cast<std::size_t>(i)] = random_vec(rng, -1, 1);
    c.x1[static_cast<std::size_t>(i)] =
        add(c.x0[static_cast<std::size_t>(i)], random_vec(rng, -0.2, 0.2));
  }
  auto point_near = [&](const std::array<Vec3d, 4>& x, double height) {
    const double u = w(rng), v = w(rng) * (1.0 - 0.5 * u);
    const Vec3d n = cross(sub(x[2], x[1]), sub(x[3], x[1]));
    const Vec3d base = add(x[1], add(mul(sub(x[2], x[1]), u), mul(sub(x[3], x[1]), v)));
    return add(base, mul(n, height / std::max(norm(n), 1e-12)));
  };
  c.x0[0] = point_near(c.x0, h(rng));
  c.x1[0] = point_near(c.x1, -h(rng));
  c.finish();
  return c;
}

/// Two random edges, the second crossing the first's neighbourhood.
Case random_edge_edge(std::mt19937_64& rng) {
  Case c;
  c.vertex_face = false;
  std::uniform_real_distribution<double> s(-0.3, 1.3), h(0.05, 0.6);
  c.x0[0] = random_vec(rng, -1, 1);
  c.x0[1] = random_vec(rng, -1, 1);
  c.x1[0] = add(c.x0[0], random_vec(rng, -0.2, 0.2));
  c.x1[1] = add(c.x0[1], random_vec(rng, -0.2, 0.2));
  const Vec3d dir = random_vec(rng, -1, 1);
  auto place = [&](const Vec3d& a, const Vec3d& b, double height) {
    const Vec3d mid = lerp(a, b, s(rng));
    const Vec3d n = cross(sub(b, a), dir);
    const Vec3d off = mul(n, height / std::max(norm(n), 1e-12));
    const double len = std::uniform_real_distribution<double>(0.3, 1.2)(rng);
    const double at = std::uniform_real_distribution<double>(-0.3, 1.3)(rng);
    return std::array<Vec3d, 2>{add(add(mid, off), mul(dir, -at * len)),
                                add(add(mid, off), mul(dir, (1 - at) * len))};
  };
  const auto e0 = place(c.x0[0], c.x0[1], h(rng));
  const auto e1 = place(c.x1[0], c.x1[1], -h(rng));
  c.x0[2] = e0[0];
  c.x0[3] = e0[1];
  c.x1[2] = e1[0];
  c.x1[3] = e1[1];
  c.finish();
  return c;
}

struct Sample {
  double f;         // coplanarity function
  double inside;    // smallest normalised inside coordinate (barycentric / segment parameters)
  double distance;  // Euclidean distance between the primitives
  bool well_shaped;
};

Sample sample(const Case& c, double t) {
  std::array<Vec3d, 4> x;
  for (std::size_t i = 0; i < 4; ++i) x[i] = lerp(c.x0[i], c.x1[i], t);
  Sample s;
  if (c.vertex_face) {
    const Vec3d &p = x[0], &a = x[1], &b = x[2], &cc = x[3];
    const Vec3d n = cross(sub(b, a), sub(cc, a));
    const double nn = dot(n, n);
    s.f = dot(n, sub(p, a));
    const double wa = dot(cross(sub(b, p), sub(cc, p)), n) / nn;
    const double wb = dot(cross(sub(cc, p), sub(a, p)), n) / nn;
    s.inside = std::min({wa, wb, 1 - wa - wb});
    s.distance = std::sqrt(tetseg::test::squared_distance_to_triangle(p, a, b, cc));
    s.well_shaped = std::sqrt(nn) > 0.1;
  } else {
    const Vec3d &a = x[0], &b = x[1], &cc = x[2], &d = x[3];
    const Vec3d n = cross(sub(b, a), sub(d, cc));
    const double nn = dot(n, n);
    s.f = dot(n, sub(cc, a));
    const double u = dot(cross(sub(cc, a), sub(d, cc)), n) / nn;
    const double v = dot(cross(sub(cc, a), sub(b, a)), n) / nn;
    s.inside = std::min({u, 1 - u, v, 1 - v});
    s.distance = segment_distance(a, b, cc, d);
    s.well_shaped = std::sqrt(nn) > 0.1;
  }
  return s;
}

tetseg::CcdResult run(const Case& c, double min_separation) {
  tetseg::CcdOptions o;
  o.min_separation = min_separation;
  const auto& a = c.x0;
  const auto& b = c.x1;
  return c.vertex_face ? tetseg::vertex_face_ccd(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3], o)
                       : tetseg::edge_edge_ccd(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3], o);
}

struct Stats {
  int clear_hits = 0, clear_misses = 0, ambiguous = 0, within = 0;
};

void cross_check(const Case& c, Stats& stats) {
  constexpr double kInsideMargin = 0.02;
  const double step = 1.0 / kSamples;
  Sample prev = sample(c, 0.0);
  double min_distance = prev.distance;
  double first_cross = -1;
  for (int i = 1; i <= kSamples; ++i) {
    const double t = i * step;
    const Sample s = sample(c, t);
    min_distance = std::min(min_distance, s.distance);
    if (first_cross < 0 && prev.f * s.f < 0 && prev.inside > kInsideMargin &&
        s.inside > kInsideMargin && prev.well_shaped && s.well_shaped)
      first_cross = t;
    prev = s;
  }
  const tetseg::CcdResult r = run(c, 0.0);
  if (first_cross >= 0) {
    ++stats.clear_hits;
    CHECK(r.hit());
    CHECK(r.toi <= first_cross);
  } else if (min_distance > c.speed * step + 1e-9) {
    ++stats.clear_misses;
    CHECK_FALSE(r.hit());
  } else {
    ++stats.ambiguous;
  }
}

/// With a minimum separation: every sampled approach closer than it must be reported no later.
void check_separation(const Case& c, double delta, Stats& stats) {
  const double step = 1.0 / kSamples;
  double first_within = -1;
  for (int i = 0; i <= kSamples && first_within < 0; ++i)
    if (sample(c, i * step).distance < delta * (1 - 1e-9)) first_within = i * step;
  const tetseg::CcdResult r = run(c, delta);
  if (first_within >= 0) {
    ++stats.within;
    CHECK(r.hit());
    CHECK(r.toi <= first_within);
  }
}

}  // namespace

TEST_CASE("Random vertex-face motions agree with dense sampling where the answer is clear.",
          "[ccd][random]") {
  std::mt19937_64 rng(20261121);
  Stats stats;
  for (int i = 0; i < 3000; ++i) {
    const Case c = random_vertex_face(rng);
    CAPTURE(i);
    cross_check(c, stats);
    check_separation(c, 0.05, stats);
  }
  WARN("vertex-face: " << stats.clear_hits << " clear hits, " << stats.clear_misses
                       << " clear misses, " << stats.ambiguous << " ambiguous, " << stats.within
                       << " within 0.05");
  CHECK(stats.clear_hits > 300);
  CHECK(stats.clear_misses > 300);
}

TEST_CASE("Random edge-edge motions agree with dense sampling where the answer is clear.",
          "[ccd][random]") {
  std::mt19937_64 rng(1121);
  Stats stats;
  for (int i = 0; i < 3000; ++i) {
    const Case c = random_edge_edge(rng);
    CAPTURE(i);
    cross_check(c, stats);
    check_separation(c, 0.05, stats);
  }
  WARN("edge-edge: " << stats.clear_hits << " clear hits, " << stats.clear_misses
                     << " clear misses, " << stats.ambiguous << " ambiguous, " << stats.within
                     << " within 0.05");
  CHECK(stats.clear_hits > 300);
  CHECK(stats.clear_misses > 300);
}
