// Triangle classification against a detector point over a step (Bernstein coefficients with
// error bounds): never contradicts the sign of the exact cubic.

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "tetseg/runtime/classify.hpp"

using namespace tetseg;

namespace {

// det[a-o, b-o, c-o] at time t in long double (positions interpolated in long double).
long double orientation_at(const double (*p0)[3], const double (*p1)[3], long double t) {
  long double x[4][3];
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k)
      x[i][k] = (1 - t) * (long double)p0[i][k] + t * (long double)p1[i][k];
  long double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k)
    u[k] = x[1][k] - x[0][k], v[k] = x[2][k] - x[0][k], w[k] = x[3][k] - x[0][k];
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

Orientation classify(const double (*p0)[3], const double (*p1)[3]) {
  return classify_orientation(p0[0], p0[1], p0[2], p0[3], p1[0], p1[1], p1[2], p1[3]);
}

}  // namespace

TEST_CASE("A definite class never contradicts the sampled sign of the cubic", "[classify]") {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1, 1);
  int definite = 0, uncertain = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    double p0[4][3], p1[4][3];
    const double scale = std::pow(10.0, (trial % 9) - 4);      // 1e-4 .. 1e4
    const double offset = trial % 3 == 0 ? 1e6 * scale : 0.0;  // far from the origin
    const double motion = trial % 2 ? 0.3 : 1.5;
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k) {
        p0[i][k] = offset + scale * u(rng);
        p1[i][k] = p0[i][k] + scale * motion * u(rng);
      }
    const Orientation o = classify(p0, p1);
    if (o == Orientation::kUncertain) {
      ++uncertain;
      continue;
    }
    ++definite;
    for (int s = 0; s <= 64; ++s) {
      const long double f = orientation_at(p0, p1, s / 64.0L);
      if (o == Orientation::kPositive) REQUIRE(f > 0);
      if (o == Orientation::kNegative) REQUIRE(f < 0);
    }
  }
  CHECK(definite > 10000);  // the bound is not uselessly loose
  CHECK(uncertain > 100);   // and sign changes do occur in the sample
}

TEST_CASE("A cubic positive at both ends but negative in between is not positive", "[classify]") {
  // o at the origin, c = (0,0,1) fixed, a and b move in the z = 0 plane:
  // f(t) = (1-2t)^2 - 0.01, positive at t = 0 and 1, negative at t = 1/2. Classifying from
  // f(0) and f(1) alone would say "positive".
  const double p0[4][3] = {{0, 0, 0}, {1, 0.1, 0}, {0.1, 1, 0}, {0, 0, 1}};
  const double p1[4][3] = {{0, 0, 0}, {-1, 0.1, 0}, {0.1, -1, 0}, {0, 0, 1}};
  REQUIRE(orientation_at(p0, p1, 0) > 0);
  REQUIRE(orientation_at(p0, p1, 1) > 0);
  REQUIRE(orientation_at(p0, p1, 0.5L) < 0);
  CHECK(classify(p0, p1) == Orientation::kUncertain);
  // The same with a double root at t = 1/2 (f = (1-2t)^2): touching zero is not positive.
  const double q0[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const double q1[4][3] = {{0, 0, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}};
  CHECK(classify(q0, q1) == Orientation::kUncertain);
}

TEST_CASE("Zero motion classifies like a static orientation test", "[classify]") {
  const double o[3] = {0.1, 0.2, 0.3}, a[3] = {1, 0, 0}, b[3] = {0, 1, 0}, c[3] = {0, 0, 1};
  CHECK(classify_orientation(o, a, b, c, o, a, b, c) == Orientation::kPositive);
  CHECK(classify_orientation(o, b, a, c, o, b, a, c) == Orientation::kNegative);
  const double d[3] = {0.5, 0.5, 0};  // coplanar with a, b and the z = 0 plane point
  const double z[3] = {0.25, 0.25, 0};
  CHECK(classify_orientation(z, a, b, d, z, a, b, d) == Orientation::kUncertain);
  const double nan[3] = {std::nan(""), 0, 0};
  CHECK(classify_orientation(o, nan, b, c, o, nan, b, c) == Orientation::kUncertain);
}
