// The closed-form triangle potential against independent quadrature (docs/charge.md).

#include <catch2/catch.hpp>
#include <cmath>

#include "../../preprocess/src/charge_potential.hpp"

using tetseg::preprocess::Vec3;
using namespace tetseg::preprocess::charge_detail;

namespace {

Vec3 lerp3(const Vec3& a, const Vec3& b, const Vec3& c, double u, double v) {
  const double w = 1.0 - u - v;
  return {w * a[0] + u * b[0] + v * c[0], w * a[1] + u * b[1] + v * c[1],
          w * a[2] + u * b[2] + v * c[2]};
}

double dist(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

double area_of(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const Vec3 v = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
               z = u[0] * v[1] - u[1] * v[0];
  return 0.5 * std::sqrt(x * x + y * y + z * z);
}

/// Uniform 4^level subdivision with the 7-point degree-5 Dunavant rule on every piece.
double quadrature(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& r, int level) {
  static const double w[7] = {0.225,
                              0.132394152788506,
                              0.132394152788506,
                              0.132394152788506,
                              0.125939180544827,
                              0.125939180544827,
                              0.125939180544827};
  static const double p[7][2] = {{1.0 / 3, 1.0 / 3},
                                 {0.059715871789770, 0.470142064105115},
                                 {0.470142064105115, 0.059715871789770},
                                 {0.470142064105115, 0.470142064105115},
                                 {0.797426985353087, 0.101286507323456},
                                 {0.101286507323456, 0.797426985353087},
                                 {0.101286507323456, 0.101286507323456}};
  const int m = 1 << level;
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; i + j < m; ++j) {
      for (int flip = 0; flip < 2; ++flip) {
        if (flip && i + j + 1 >= m) continue;
        Vec3 t0, t1, t2;
        if (!flip) {
          t0 = lerp3(a, b, c, double(i) / m, double(j) / m);
          t1 = lerp3(a, b, c, double(i + 1) / m, double(j) / m);
          t2 = lerp3(a, b, c, double(i) / m, double(j + 1) / m);
        } else {
          t0 = lerp3(a, b, c, double(i + 1) / m, double(j) / m);
          t1 = lerp3(a, b, c, double(i + 1) / m, double(j + 1) / m);
          t2 = lerp3(a, b, c, double(i) / m, double(j + 1) / m);
        }
        const double area = area_of(t0, t1, t2);
        for (int q = 0; q < 7; ++q)
          sum += w[q] * area / dist(lerp3(t0, t1, t2, p[q][0], p[q][1]), r);
      }
    }
  }
  return sum;
}

/// In-plane point inside the triangle: integral = sum over edges of the integral over the
/// polar angle of the distance to the edge, t / cos(phi - phi_n), by composite Simpson.
double polar_in_plane(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& r) {
  // Work in the triangle's plane z = 0 (the tests use such triangles).
  const Vec3* v[3] = {&a, &b, &c};
  double sum = 0.0;
  for (int e = 0; e < 3; ++e) {
    const Vec3& p = *v[e];
    const Vec3& q = *v[(e + 1) % 3];
    const double a0 = std::atan2(p[1] - r[1], p[0] - r[0]);
    double a1 = std::atan2(q[1] - r[1], q[0] - r[0]);
    while (a1 < a0) a1 += 2 * M_PI;
    // Distance along direction phi from r to the line pq.
    const double ex = q[0] - p[0], ey = q[1] - p[1];
    const int n = 20000;
    auto rho = [&](double phi) {
      const double dx = std::cos(phi), dy = std::sin(phi);
      // r + s d = p + u e  ->  s = cross(p - r, e) / cross(d, e)
      return ((p[0] - r[0]) * ey - (p[1] - r[1]) * ex) / (dx * ey - dy * ex);
    };
    const double h = (a1 - a0) / n;
    double s = rho(a0) + rho(a1);
    for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * rho(a0 + i * h);
    sum += s * h / 3.0;
  }
  return sum;
}

}  // namespace

TEST_CASE("The closed-form triangle potential matches quadrature", "[charge][potential]") {
  const Vec3 a{0.0, 0.0, 0.0}, b{1.0, 0.0, 0.0}, c{0.3, 0.8, 0.0};
  SECTION("A point well off the plane above the triangle agrees to 1e-7.") {
    const Vec3 r{0.3, 0.2, 0.5};
    CHECK(triangle_potential(a, b, c, r) == Approx(quadrature(a, b, c, r, 5)).epsilon(1e-7));
  }
  SECTION("Points off the plane beside the triangle, over a corner and below agree to 1e-7.") {
    // The angle terms are taken as one solid angle; these check it where the projection of r
    // falls outside the triangle (some edge terms negative) and on either side of the plane.
    for (const Vec3 r : {Vec3{1.5, 1.0, 0.4}, Vec3{-0.4, 0.3, 0.25}, Vec3{0.5, -0.6, -0.3},
                         Vec3{1.0, 0.0, 0.3}, Vec3{0.3, 0.8, -0.05}, Vec3{0.45, 0.3, -0.7}}) {
      CAPTURE(r[0], r[1], r[2]);
      CHECK(triangle_potential(a, b, c, r) == Approx(quadrature(a, b, c, r, 7)).epsilon(1e-7));
    }
  }
  SECTION("A point just off an edge agrees to 1e-5.") {
    const Vec3 r{0.5, -0.01, 0.02};
    CHECK(triangle_potential(a, b, c, r) == Approx(quadrature(a, b, c, r, 8)).epsilon(1e-5));
  }
  SECTION("A point in the plane outside the triangle agrees to 1e-7.") {
    const Vec3 r{1.5, 1.0, 0.0};
    CHECK(triangle_potential(a, b, c, r) == Approx(quadrature(a, b, c, r, 6)).epsilon(1e-7));
  }
  SECTION("A point on the extension of an edge line is finite and agrees.") {
    const Vec3 r{1.6, 0.0, 0.0};
    const double v = triangle_potential(a, b, c, r);
    CHECK(std::isfinite(v));
    CHECK(v == Approx(quadrature(a, b, c, r, 7)).epsilon(1e-6));
  }
  SECTION("A far point agrees with quadrature and with the point charge to 0.1%.") {
    const Vec3 r{10.0, 5.0, 3.0};
    const double v = triangle_potential(a, b, c, r);
    CHECK(v == Approx(quadrature(a, b, c, r, 3)).epsilon(1e-9));
    const Vec3 g{(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, 0.0};
    CHECK(v == Approx(area_of(a, b, c) / dist(g, r)).epsilon(1e-3));
  }
  SECTION("The point-charge form is within 0.2% at five diameters.") {
    const Vec3 g{(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, 0.0};
    const double r5 = 5.0 * dist(b, c);  // bc is the longest edge
    for (const Vec3 dir : {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}, Vec3{0.6, 0.0, 0.8}}) {
      const Vec3 r{g[0] + r5 * dir[0], g[1] + r5 * dir[1], g[2] + r5 * dir[2]};
      CAPTURE(dir[0], dir[1], dir[2]);
      CHECK(triangle_potential(a, b, c, r) == Approx(area_of(a, b, c) / r5).epsilon(2e-3));
    }
  }
  SECTION("The orientation of the triangle does not change the potential.") {
    const Vec3 r{0.2, 0.4, -0.3};
    CHECK(triangle_potential(a, b, c, r) == Approx(triangle_potential(a, c, b, r)).epsilon(1e-14));
  }
}

TEST_CASE("The self term at the centroid is the singular integral", "[charge][potential]") {
  SECTION("An equilateral triangle of side s gives sqrt(3) s ln(2 + sqrt 3).") {
    const double s = 0.7;
    const Vec3 a{0, 0, 0}, b{s, 0, 0}, c{s / 2, s * std::sqrt(3.0) / 2, 0};
    CHECK(triangle_self_potential(a, b, c) ==
          Approx(std::sqrt(3.0) * s * std::log(2 + std::sqrt(3.0))).epsilon(1e-12));
  }
  SECTION("A scalene triangle matches the general formula and polar quadrature.") {
    const Vec3 a{0, 0, 0}, b{1.3, 0.1, 0}, c{0.2, 0.6, 0};
    const Vec3 g{(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, 0.0};
    const double self = triangle_self_potential(a, b, c);
    CHECK(self == Approx(triangle_potential(a, b, c, g)).epsilon(1e-12));
    CHECK(self == Approx(polar_in_plane(a, b, c, g)).epsilon(1e-9));
  }
}

TEST_CASE("Degenerate and malformed surfaces are rejected", "[charge]") {
  const std::vector<Vec3> pts = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0}};
  SECTION("A zero-area triangle names the triangle.") {
    const std::vector<tetseg::preprocess::Tri> tris = {{0, 2, 1}, {0, 1, 3}, {0, 1, 4}};
    try {
      make_panels(pts, tris, "bad.off");
      FAIL("no exception");
    } catch (const tetseg::preprocess::InputError& e) {
      CHECK(e.file() == "bad.off");
      CHECK(std::string(e.what()).find("triangle 2") != std::string::npos);
      CHECK(std::string(e.what()).find("degenerate") != std::string::npos);
    }
  }
  SECTION("An index out of range is an input error.") {
    const std::vector<tetseg::preprocess::Tri> tris = {{0, 2, 7}};
    CHECK_THROWS_AS(make_panels(pts, tris, "x"), tetseg::preprocess::InputError);
  }
  SECTION("A non-finite coordinate is an input error.") {
    std::vector<Vec3> bad = pts;
    bad[3][1] = std::nan("");
    const std::vector<tetseg::preprocess::Tri> tris = {{0, 2, 1}};
    CHECK_THROWS_AS(make_panels(bad, tris, "x"), tetseg::preprocess::InputError);
  }
  SECTION("No triangles is an input error.") {
    CHECK_THROWS_AS(make_panels(pts, {}, "x"), tetseg::preprocess::InputError);
  }
}
