// The floating-point fast paths of the elementary CCD tests against exact rational arithmetic
// (GMP): the filtered 2D orientation of the plane certificates (runtime/src/ccd_plane.hpp), the
// float Bernstein subdivision with its running error bound (runtime/src/ccd_bernstein.hpp) and
// the coplanarity cubic of the whole step in doubles (step_cubic,
// runtime/src/ccd_certificates.hpp). Each must never claim what exact arithmetic contradicts, and
// each bound is load-bearing: scaled down (an eighth of it), the same inputs produce wrong claims.

#include <array>
#include <cmath>
#include <random>

#include <gmpxx.h>
#include <catch2/catch.hpp>

#include "../../runtime/src/ccd_bernstein.hpp"
#include "../../runtime/src/ccd_certificates.hpp"
#include "../../runtime/src/ccd_plane.hpp"
#include "../../runtime/src/orientation_terms.hpp"

namespace {

using tetseg::ccd_detail::FloatBernstein;
using tetseg::ccd_detail::orient2d_sign;
using tetseg::ccd_detail::Point3;

/// Exact sign of (a - c) x (b - c) on the axes (0, 1).
int exact_orient2d(const Point3& a, const Point3& b, const Point3& c) {
  const mpq_class acx = mpq_class(a[0]) - c[0], bcx = mpq_class(b[0]) - c[0];
  const mpq_class acy = mpq_class(a[1]) - c[1], bcy = mpq_class(b[1]) - c[1];
  return sgn(mpq_class(acx * bcy - acy * bcx));
}

/// Nearly collinear triples: c on the line through a and b, rounded, then nudged by a few
/// ulps; coordinates over many magnitudes, offsets far from the origin. These are the inputs
/// whose rounding errors come closest to the bound.
struct NearCollinear {
  std::mt19937_64 rng{20261128};
  std::uniform_real_distribution<double> unit{-1.0, 1.0};
  std::uniform_int_distribution<int> exponent{-30, 30};
  std::uniform_int_distribution<int> ulps{-4, 4};
  std::array<Point3, 3> next() {
    const double scale = std::ldexp(1.0, exponent(rng));
    const double offset = unit(rng) < 0.0 ? 0.0 : scale * std::ldexp(1.0, exponent(rng) / 3 + 10);
    const Point3 a{offset + scale * unit(rng), offset + scale * unit(rng), 0.0};
    const Point3 b{offset + scale * unit(rng), offset + scale * unit(rng), 0.0};
    const double s = 4.0 * unit(rng);
    Point3 c{a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), 0.0};
    for (int k = 0; k < 2; ++k)
      for (int n = ulps(rng); n != 0; n += n > 0 ? -1 : 1)
        c[k] = std::nextafter(c[k], n > 0 ? INFINITY : -INFINITY);
    return {a, b, c};
  }
};

}  // namespace

TEST_CASE("The filtered 2D orientation never claims a wrong sign, and an eighth of its bound does",
          "[ccd][filter]") {
  NearCollinear gen;
  int decided = 0, wrong = 0, wrong_scaled = 0;
  for (int i = 0; i < 400000; ++i) {
    const auto [a, b, c] = gen.next();
    const int exact = exact_orient2d(a, b, c);
    const int s = orient2d_sign(a, b, c, 0, 1);
    if (s != 0) {
      ++decided;
      if (s != exact) ++wrong;
    }
    const int scaled = orient2d_sign(a, b, c, 0, 1, 0.125);
    if (scaled != 0 && scaled != exact) ++wrong_scaled;
  }
  INFO(decided << " decided, " << wrong << " wrong; with an eighth of the bound " << wrong_scaled
               << " wrong");
  CHECK(wrong == 0);
  CHECK(decided > 100000);  // the filter decides most of these near-collinear triples
  CHECK(wrong_scaled > 0);  // the bound is load-bearing
}

namespace {

/// Exact de Casteljau halving of rational coefficients.
void exact_split(const std::array<mpq_class, 5>& c, int n, std::array<mpq_class, 5>& left,
                 std::array<mpq_class, 5>& right) {
  std::array<mpq_class, 5> w = c;
  left[0] = w[0];
  right[n] = w[n];
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i + r <= n; ++i) w[i] = (w[i] + w[i + 1]) / 2;
    left[r] = w[0];
    right[n - r] = w[n - r];
  }
}

/// Largest |computed - exact| over the coefficients, as a multiple of the claimed bound err;
/// > 1 means the bound was violated.
double violation(const FloatBernstein& p, const std::array<mpq_class, 5>& exact) {
  double worst = 0.0;
  for (int i = 0; i <= p.degree; ++i) {
    const mpq_class diff = abs(mpq_class(p.c[i]) - exact[i]);
    worst = std::max(worst, diff.get_d() / p.err);
  }
  return worst;
}

}  // namespace

TEST_CASE("Float Bernstein halving stays within its error bound, and an eighth of it does not",
          "[ccd][filter]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-20, 20);
  std::uniform_int_distribution<int> side(0, 1);
  double worst = 0.0, worst_scaled = 0.0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int n = 3 + trial % 2;
    const double scale = std::ldexp(1.0, exponent(rng));
    FloatBernstein p{{}, n, 0.0}, q{{}, n, 0.0};
    std::array<mpq_class, 5> exact{}, exact_q{};
    for (int i = 0; i <= n; ++i) {
      p.c[i] = q.c[i] = scale * (unit(rng) + (i % 2 == 0 ? 0.5 : -0.25));
      exact[i] = exact_q[i] = p.c[i];
    }
    // Up to 40 halvings down one random path, each checked against exact arithmetic.
    for (int level = 0; level < 40; ++level) {
      FloatBernstein left{}, right{}, left_q{}, right_q{};
      std::array<mpq_class, 5> exact_left, exact_right, exact_left_q, exact_right_q;
      tetseg::ccd_detail::split_half(p, left, right);
      tetseg::ccd_detail::split_half(q, left_q, right_q, 0.125);
      exact_split(exact, n, exact_left, exact_right);
      exact_split(exact_q, n, exact_left_q, exact_right_q);
      const bool go_left = side(rng) == 0;
      p = go_left ? left : right;
      q = go_left ? left_q : right_q;
      exact = go_left ? exact_left : exact_right;
      exact_q = go_left ? exact_left_q : exact_right_q;
      worst = std::max(worst, violation(p, exact));
      worst_scaled = std::max(worst_scaled, violation(q, exact_q));
    }
  }
  INFO("largest error / bound: " << worst << "; with an eighth of the charge: " << worst_scaled);
  CHECK(worst <= 1.0);
  CHECK(worst_scaled > 1.0);  // the charge per level is load-bearing
}

TEST_CASE(
    "Float de Casteljau at any parameter stays within its bound, and an eighth of it does not",
    "[ccd][filter]") {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> parameter(0.0, 1.0);
  std::uniform_int_distribution<int> exponent(-20, 20);
  double worst = 0.0, worst_scaled = 0.0;
  for (int trial = 0; trial < 200000; ++trial) {
    const int n = 3 + trial % 2;
    const double scale = std::ldexp(1.0, exponent(rng));
    FloatBernstein p{{}, n, 0.0};
    std::array<mpq_class, 5> w{};
    for (int i = 0; i <= n; ++i) {
      p.c[i] = scale * (unit(rng) + (i % 2 == 0 ? 0.5 : -0.25));
      w[i] = p.c[i];
    }
    const double lambda = parameter(rng);
    // Exact left part on [0, lambda]: de Casteljau in rationals.
    std::array<mpq_class, 5> exact{};
    exact[0] = w[0];
    for (int r = 1; r <= n; ++r) {
      for (int i = 0; i + r <= n; ++i) w[i] = w[i] + mpq_class(lambda) * (w[i + 1] - w[i]);
      exact[r] = w[0];
    }
    worst = std::max(worst, violation(tetseg::ccd_detail::left_part(p, lambda), exact));
    worst_scaled =
        std::max(worst_scaled, violation(tetseg::ccd_detail::left_part(p, lambda, 0.125), exact));
  }
  INFO("largest error / bound: " << worst << "; with an eighth of the charge: " << worst_scaled);
  CHECK(worst <= 1.0);
  CHECK(worst_scaled > 1.0);  // the charge per level is load-bearing
}

TEST_CASE("Float de Casteljau's right part stays within its bound, and an eighth of it does not",
          "[ccd][filter]") {
  // right_part at grid points lambda = k / 2^m (the root leaf's end, where 1 - lambda is exact).
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-20, 20);
  std::uniform_int_distribution<int> level(1, 40);
  double worst = 0.0, worst_scaled = 0.0;
  for (int trial = 0; trial < 200000; ++trial) {
    const int n = 3 + trial % 2;
    const double scale = std::ldexp(1.0, exponent(rng));
    FloatBernstein p{{}, n, 0.0};
    std::array<mpq_class, 5> w{};
    for (int i = 0; i <= n; ++i) {
      p.c[i] = scale * (unit(rng) + (i % 2 == 0 ? 0.5 : -0.25));
      w[i] = p.c[i];
    }
    const int m = level(rng);
    const double grid = std::ldexp(1.0, -m);
    const double lambda = std::floor(0.5 * (unit(rng) + 1.0) / grid) * grid;
    // Exact right part on [lambda, 1]: de Casteljau in rationals, the last coefficients.
    std::array<mpq_class, 5> exact{};
    exact[n] = w[n];
    for (int r = 1; r <= n; ++r) {
      for (int i = 0; i + r <= n; ++i) w[i] = w[i] + mpq_class(lambda) * (w[i + 1] - w[i]);
      exact[n - r] = w[n - r];
    }
    worst = std::max(worst, violation(tetseg::ccd_detail::right_part(p, lambda), exact));
    worst_scaled =
        std::max(worst_scaled, violation(tetseg::ccd_detail::right_part(p, lambda, 0.125), exact));
  }
  INFO("largest error / bound: " << worst << "; with an eighth of the charge: " << worst_scaled);
  CHECK(worst <= 1.0);
  CHECK(worst_scaled > 1.0);  // the charge per level is load-bearing
}

namespace {

using Moving = std::array<Point3, 8>;  // o, a, b, c at t = 0, then at t = 1

/// Exact Bernstein coefficients on [0, 1] of det[a(t) - o(t), b(t) - o(t), c(t) - o(t)].
std::array<mpq_class, 5> exact_step_cubic(const Moving& x) {
  using Q3 = std::array<mpq_class, 3>;
  auto diff = [&](int i, int end) {
    Q3 d;
    for (int k = 0; k < 3; ++k) d[k] = mpq_class(x[4 * end + i][k]) - x[4 * end][k];
    return d;
  };
  auto det = [](const Q3& u, const Q3& v, const Q3& w) {
    return mpq_class(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                     u[2] * (v[0] * w[1] - v[1] * w[0]));
  };
  const Q3 u[2] = {diff(1, 0), diff(1, 1)}, v[2] = {diff(2, 0), diff(2, 1)},
           w[2] = {diff(3, 0), diff(3, 1)};
  std::array<mpq_class, 5> c{};
  c[0] = det(u[0], v[0], w[0]);
  c[1] = (det(u[1], v[0], w[0]) + det(u[0], v[1], w[0]) + det(u[0], v[0], w[1])) / 3;
  c[2] = (det(u[0], v[1], w[1]) + det(u[1], v[0], w[1]) + det(u[1], v[1], w[0])) / 3;
  c[3] = det(u[1], v[1], w[1]);
  return c;
}

}  // namespace

TEST_CASE(
    "The whole step's coplanarity cubic in doubles stays within its bound, and a fraction "
    "of it does not",
    "[ccd][filter]") {
  // Four points nearly coplanar at both ends (c on the plane of o, a, b, nudged by a few ulps),
  // over many scales and far from the origin: the cancellations that come closest to the bound.
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-20, 20);
  std::uniform_int_distribution<int> ulps(-4, 4);
  double worst = 0.0, worst_scaled = 0.0;
  for (int trial = 0; trial < 100000; ++trial) {
    const double scale = std::ldexp(1.0, exponent(rng));
    const double offset = trial % 2 == 0 ? 0.0 : scale * std::ldexp(1.0, exponent(rng) / 2 + 10);
    Moving x;
    for (int end = 0; end < 2; ++end) {
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) x[4 * end + i][k] = offset + scale * unit(rng);
      const double s = 2.0 * unit(rng), r = 2.0 * unit(rng);
      for (int k = 0; k < 3; ++k) {
        const Point3 &o = x[4 * end], &a = x[4 * end + 1], &b = x[4 * end + 2];
        double c = o[k] + s * (a[k] - o[k]) + r * (b[k] - o[k]);
        for (int n = ulps(rng); n != 0; n += n > 0 ? -1 : 1)
          c = std::nextafter(c, n > 0 ? INFINITY : -INFINITY);
        x[4 * end + 3][k] = c;
      }
    }
    const tetseg::BernsteinCubic k =
        tetseg::orientation_detail::cubic(x[0].data(), x[1].data(), x[2].data(), x[3].data(),
                                          x[4].data(), x[5].data(), x[6].data(), x[7].data());
    const auto exact = exact_step_cubic(x);
    worst = std::max(worst, violation(tetseg::ccd_detail::step_cubic(k), exact));
    worst_scaled =
        std::max(worst_scaled, violation(tetseg::ccd_detail::step_cubic(k, 0.125), exact));
  }
  INFO("largest error / bound: " << worst << "; with an eighth of the bound: " << worst_scaled);
  CHECK(worst <= 1.0);
  CHECK(worst_scaled > 1.0);  // the bound is load-bearing
}

TEST_CASE(
    "The two-lane cross products of the interval checks enclose the exact values, and an "
    "eighth of their radii does not",
    "[ccd][filter][lanes]") {
  // cross_sums (ccd_forms.hpp) computes its four cross products two at a time (Iv2): each
  // radius must cover the rounding of the midpoint. Exact input vectors over many scales, some
  // nearly parallel (cancellation), against the exact GMP cross products.
  using tetseg::ccd_detail::Iv;
  using tetseg::ccd_detail::Slot;
  using tetseg::ccd_detail::Vec;
  std::mt19937_64 rng(2511);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-40, 40);
  auto vec = [&](double scale) {
    return Vec<Iv>{{scale * unit(rng), 0.0}, {scale * unit(rng), 0.0}, {scale * unit(rng), 0.0}};
  };
  using Q3 = std::array<mpq_class, 3>;
  auto exact_vec = [](const Vec<Iv>& v) { return Q3{v.x.m, v.y.m, v.z.m}; };
  auto cross = [](const Q3& a, const Q3& b) {
    return Q3{mpq_class(a[1] * b[2] - a[2] * b[1]), mpq_class(a[2] * b[0] - a[0] * b[2]),
              mpq_class(a[0] * b[1] - a[1] * b[0])};
  };
  // Largest |exact - midpoint| / radius over all components.
  double worst = 0.0;
  auto record = [&](const Vec<Iv>& got, const Q3& exact) {
    const Iv c[3] = {got.x, got.y, got.z};
    for (int k = 0; k < 3; ++k) {
      const double error = std::fabs(mpq_class(exact[k] - c[k].m).get_d());
      if (error > 0.0) worst = std::max(worst, error / c[k].r);
    }
  };
  for (int trial = 0; trial < 100000; ++trial) {
    const double scale = std::ldexp(1.0, exponent(rng));
    Slot<Iv> w1{{vec(scale), vec(scale)}}, w2{{vec(scale), vec(scale)}};
    if (trial % 2 == 0) {  // nearly parallel: w2 ~ w1 rounded
      for (int i = 0; i < 2; ++i) {
        w2.v[i] = {{w1.v[i].x.m * 3.0 + unit(rng) * scale * 1e-12, 0.0},
                   {w1.v[i].y.m * 3.0, 0.0},
                   {w1.v[i].z.m * 3.0, 0.0}};
      }
    }
    const auto sums = tetseg::ccd_detail::cross_sums(w1, w2);
    const Q3 a0 = exact_vec(w1.v[0]), a1 = exact_vec(w1.v[1]), b0 = exact_vec(w2.v[0]),
             b1 = exact_vec(w2.v[1]);
    const Q3 m0 = cross(a0, b1), m1 = cross(a1, b0);
    record(sums.c[0], cross(a0, b0));
    record(sums.c[1],
           Q3{mpq_class(m0[0] + m1[0]), mpq_class(m0[1] + m1[1]), mpq_class(m0[2] + m1[2])});
    record(sums.c[2], cross(a1, b1));
  }
  INFO("largest error / radius: " << worst);
  CHECK(worst <= 1.0);
  CHECK(worst * 8.0 > 1.0);  // an eighth of the radius is violated: the radii are load-bearing
}
