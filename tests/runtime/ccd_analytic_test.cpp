// Elementary CCD tests on generated motions with an analytic time of impact, under exact
// transforms (axis permutations, sign flips, power-of-two scales 2^-13..2^13 ~ 1e-4..1e4, and
// translations by 2^20 ~ 1e6) so the transformed problem has exactly the same answer.

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "tetseg/runtime/ccd.hpp"

namespace {

using tetseg::CcdOptions;
using tetseg::CcdOutcome;
using tetseg::CcdResult;
using tetseg::Vec3d;

struct Transform {
  std::array<int, 3> perm{0, 1, 2};
  std::array<double, 3> sign{1, 1, 1};
  double scale = 1.0;
  Vec3d shift{0, 0, 0};
  Vec3d operator()(const Vec3d& x) const {
    Vec3d y;
    for (int k = 0; k < 3; ++k)
      y[static_cast<std::size_t>(k)] =
          shift[static_cast<std::size_t>(k)] +
          scale * sign[static_cast<std::size_t>(k)] *
              x[static_cast<std::size_t>(perm[static_cast<std::size_t>(k)])];
    return y;
  }
  /// True when x maps to a double that maps back to x exactly (the transform is exact on x).
  bool exact_on(const Vec3d& x) const {
    const Vec3d y = (*this)(x);
    for (int k = 0; k < 3; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      const double back = (y[ku] - shift[ku]) / scale * sign[ku];
      if (back != x[static_cast<std::size_t>(perm[ku])]) return false;
    }
    return true;
  }
  /// Relative precision of the transformed geometry (ulp of the shift over the scale).
  double resolution() const {
    const double m =
        std::max({std::fabs(shift[0]), std::fabs(shift[1]), std::fabs(shift[2]), scale});
    return m * 0x1p-52 / scale;
  }
  std::string name() const {
    return "perm " + std::to_string(perm[0]) + std::to_string(perm[1]) + std::to_string(perm[2]) +
           " scale " + std::to_string(scale) + " shift " + std::to_string(shift[0]);
  }
};

/// All exact transforms used by the sweeps.
std::vector<Transform> transforms() {
  std::vector<Transform> out;
  const std::array<std::array<int, 3>, 3> perms{{{0, 1, 2}, {1, 2, 0}, {2, 0, 1}}};
  const std::array<double, 5> scales{0x1p-13, 0x1p-5, 1.0, 0x1p7, 0x1p13};
  const std::array<Vec3d, 3> shifts{
      {{0, 0, 0}, {0x1p20, -0x1p20, 0x1p19}, {-3 * 0x1p19, 5.0, 0x1p20}}};
  int flip = 0;
  for (const auto& p : perms)
    for (double s : scales)
      for (const auto& sh : shifts) {
        Transform t;
        t.perm = p;
        t.scale = s;
        t.shift = sh;
        ++flip;
        t.sign = {flip % 2 ? -1.0 : 1.0, flip % 3 ? 1.0 : -1.0, 1.0};
        out.push_back(t);
      }
  return out;
}

struct Motion {
  std::array<Vec3d, 4> x0;  // vf: p a b c; ee: a b c d
  std::array<Vec3d, 4> x1;
};

bool exact_on(const Transform& t, const Motion& m) {
  for (std::size_t i = 0; i < 4; ++i)
    if (!t.exact_on(m.x0[i]) || !t.exact_on(m.x1[i])) return false;
  return true;
}

CcdResult run(bool vertex_face, const Motion& m, const Transform& t, const CcdOptions& o = {}) {
  std::array<Vec3d, 4> y0, y1;
  for (std::size_t i = 0; i < 4; ++i) {
    y0[i] = t(m.x0[i]);
    y1[i] = t(m.x1[i]);
  }
  return vertex_face
             ? tetseg::vertex_face_ccd(y0[0], y0[1], y0[2], y0[3], y1[0], y1[1], y1[2], y1[3], o)
             : tetseg::edge_edge_ccd(y0[0], y0[1], y0[2], y0[3], y1[0], y1[1], y1[2], y1[3], o);
}

const Vec3d kA{0, 0, 0}, kB{1, 0, 0}, kC{0, 1, 0};

/// Static unit right triangle in z = 0 and a point moving from p0 to p1.
Motion point_vs_triangle(const Vec3d& p0, const Vec3d& p1) {
  return {{p0, kA, kB, kC}, {p1, kA, kB, kC}};
}

/// Static edge (-1,0,0)-(1,0,0) and an edge moving from (c0,d0) to (c1,d1).
Motion edge_vs_xaxis(const Vec3d& c0, const Vec3d& d0, const Vec3d& c1, const Vec3d& d1) {
  const Vec3d a{-1, 0, 0}, b{1, 0, 0};
  return {{a, b, c0, d0}, {a, b, c1, d1}};
}

/// Expects a contact in (0,1] with toi <= truth and toi >= truth - slack, for every transform
/// that is exact on the motion (the others change the problem and are skipped).
void expect_contact(bool vf, const Motion& m, double truth) {
  int tested = 0;
  for (const auto& t : transforms()) {
    if (!exact_on(t, m)) continue;
    ++tested;
    CAPTURE(t.name());
    const CcdResult r = run(vf, m, t);
    REQUIRE(r.outcome == CcdOutcome::kContact);
    CHECK(r.toi <= truth);
    CHECK(r.toi >= truth - 1e-6 - 64 * t.resolution());
  }
  CHECK(tested >= 30);
}

void expect_outcome(bool vf, const Motion& m, CcdOutcome outcome, const CcdOptions& o = {}) {
  int tested = 0;
  for (const auto& t : transforms()) {
    if (!exact_on(t, m)) continue;
    ++tested;
    CAPTURE(t.name());
    CcdOptions scaled = o;
    scaled.min_separation = o.min_separation * t.scale;
    const CcdResult r = run(vf, m, t, scaled);
    CHECK(r.outcome == outcome);
    if (outcome == CcdOutcome::kContactAtStart) CHECK(r.toi == 0.0);
  }
  CHECK(tested >= 30);
}

}  // namespace

TEST_CASE("A vertex meeting a triangle is found at its analytic time of impact.", "[ccd]") {
  SECTION("A vertex falling straight through the interior hits at t = 3/4.") {
    expect_contact(true, point_vs_triangle({0.25, 0.25, 0.75}, {0.25, 0.25, -0.25}), 0.75);
  }
  SECTION("A vertex crossing exactly through an edge of the triangle hits (closed test).") {
    expect_contact(true, point_vs_triangle({0.5, 0, 0.75}, {0.5, 0, -0.25}), 0.75);
    expect_contact(true, point_vs_triangle({0.5, 0.5, 0.75}, {0.5, 0.5, -0.25}), 0.75);
  }
  SECTION("A vertex crossing exactly through a corner of the triangle hits.") {
    expect_contact(true, point_vs_triangle({0, 0, 0.75}, {0, 0, -0.25}), 0.75);
    expect_contact(true, point_vs_triangle({1, 0, 0.75}, {1, 0, -0.25}), 0.75);
  }
  SECTION("A vertex and a triangle moving towards each other meet at t = 2/3.") {
    const Motion m{{Vec3d{0.25, 0.25, 1}, kA, kB, kC},
                   {Vec3d{0.25, 0.25, 0}, Vec3d{0, 0, 0.5}, Vec3d{1, 0, 0.5}, Vec3d{0, 1, 0.5}}};
    expect_contact(true, m, 2.0 / 3.0 + 1e-15);
  }
  SECTION("A vertex passing just outside the hypotenuse misses.") {
    expect_outcome(true, point_vs_triangle({0.5 + 0x1p-30, 0.5, 0.75}, {0.5 + 0x1p-30, 0.5, -0.25}),
                   CcdOutcome::kNoContact);
  }
  SECTION("A vertex touching the plane exactly at t = 1 is reported before the end.") {
    expect_contact(true, point_vs_triangle({0.25, 0.25, 1}, {0.25, 0.25, 0}), 1.0);
  }
}

TEST_CASE("Near-degenerate vertex-face motions are decided correctly.", "[ccd]") {
  SECTION("A vertex moving in the plane of the triangle enters it at t = 1/2.") {
    expect_contact(true, point_vs_triangle({-1, 0.25, 0}, {1, 0.25, 0}), 0.5);
  }
  SECTION("A vertex moving in the plane of the triangle beside it never touches.") {
    expect_outcome(true, point_vs_triangle({-1, 2, 0}, {1, 2, 0}), CcdOutcome::kNoContact);
  }
  SECTION("A vertex sliding on the face is in contact at the start.") {
    expect_outcome(true, point_vs_triangle({0.125, 0.125, 0}, {0.25, 0.25, 0}),
                   CcdOutcome::kContactAtStart);
  }
  SECTION("A vertex sliding just above the face never touches it.") {
    expect_outcome(true, point_vs_triangle({0.125, 0.125, 0x1p-30}, {0.25, 0.25, 0x1p-30}),
                   CcdOutcome::kNoContact);
  }
  SECTION("Zero motion while touching is a contact at the start.") {
    expect_outcome(true, point_vs_triangle({0.25, 0.25, 0}, {0.25, 0.25, 0}),
                   CcdOutcome::kContactAtStart);
    expect_outcome(true, point_vs_triangle({0, 0.5, 0}, {0, 0.5, 0}), CcdOutcome::kContactAtStart);
  }
  SECTION("Zero motion while apart is no contact.") {
    expect_outcome(true, point_vs_triangle({0.25, 0.25, 0.5}, {0.25, 0.25, 0.5}),
                   CcdOutcome::kNoContact);
    expect_outcome(true, point_vs_triangle({0.75, 0.75, 0}, {0.75, 0.75, 0}),
                   CcdOutcome::kNoContact);
  }
  SECTION("A vertex leaving the face at t = 0 is a contact at the start.") {
    expect_outcome(true, point_vs_triangle({0.25, 0.25, 0}, {0.25, 0.25, 1}),
                   CcdOutcome::kContactAtStart);
  }
  SECTION("A degenerate (collinear) triangle is hit by a vertex crossing its segment.") {
    const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{2, 0, 0};
    expect_contact(true, {{Vec3d{0.5, -1, 0.5}, a, b, c}, {Vec3d{0.5, 1, -0.5}, a, b, c}}, 0.5);
  }
  SECTION("A degenerate triangle far from the vertex is not hit.") {
    const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{2, 0, 0};
    expect_outcome(true, {{Vec3d{0.5, 1, 0.5}, a, b, c}, {Vec3d{0.5, 2, -0.5}, a, b, c}},
                   CcdOutcome::kNoContact);
  }
}

TEST_CASE("Two edges meeting are found at their analytic time of impact.", "[ccd]") {
  SECTION("Crossing edges meet at t = 3/4.") {
    expect_contact(false, edge_vs_xaxis({0, -1, 0.75}, {0, 1, 0.75}, {0, -1, -0.25}, {0, 1, -0.25}),
                   0.75);
  }
  SECTION("An edge passing through the endpoint of the other hits (closed test).") {
    expect_contact(false, edge_vs_xaxis({1, -1, 0.75}, {1, 1, 0.75}, {1, -1, -0.25}, {1, 1, -0.25}),
                   0.75);
  }
  SECTION("Two endpoints meeting exactly hit.") {
    expect_contact(
        false, edge_vs_xaxis({1, 0, 0.75}, {2, 0.5, 0.75}, {1, 0, -0.25}, {2, 0.5, -0.25}), 0.75);
  }
  SECTION("An edge passing beside the end of the other misses.") {
    expect_outcome(false,
                   edge_vs_xaxis({1 + 0x1p-30, -1, 0.75}, {1 + 0x1p-30, 1, 0.75},
                                 {1 + 0x1p-30, -1, -0.25}, {1 + 0x1p-30, 1, -0.25}),
                   CcdOutcome::kNoContact);
  }
}

TEST_CASE("Near-degenerate edge-edge motions are decided correctly.", "[ccd]") {
  SECTION("Parallel coplanar edges that overlap meet at t = 1/2.") {
    expect_contact(false, edge_vs_xaxis({0, 1, 0}, {2, 1, 0}, {0, -1, 0}, {2, -1, 0}), 0.5);
  }
  SECTION("Parallel coplanar edges that do not overlap never touch.") {
    expect_outcome(false, edge_vs_xaxis({2, 1, 0}, {3, 1, 0}, {2, -1, 0}, {3, -1, 0}),
                   CcdOutcome::kNoContact);
  }
  SECTION("Parallel coplanar edges side by side, like neighbours in a grid, never touch.") {
    // Regression: cloth-funnel frame 227, edges 9330-9340 and 9331-9341 (static, coplanar,
    // parallel, boxes touching) were reported in contact at the start.
    expect_outcome(false, edge_vs_xaxis({-1, 1, 0}, {1, 1, 0}, {-1, 1, 0}, {1, 1, 0}),
                   CcdOutcome::kNoContact);
    const Vec3d a{-1, 1.25, -2}, b{-1.25, 1, -2}, c{-0.75, 1.25, -2}, d{-1, 1, -2};
    expect_outcome(false, {{a, b, c, d}, {a, b, c, d}}, CcdOutcome::kNoContact);
  }
  SECTION("Parallel edges in parallel planes never touch.") {
    expect_outcome(false, edge_vs_xaxis({0, 1, 0.5}, {2, 1, 0.5}, {0, -1, 0.5}, {2, -1, 0.5}),
                   CcdOutcome::kNoContact);
  }
  SECTION("Collinear overlapping edges without motion are in contact at the start.") {
    expect_outcome(false, edge_vs_xaxis({0, 0, 0}, {2, 0, 0}, {0, 0, 0}, {2, 0, 0}),
                   CcdOutcome::kContactAtStart);
  }
  SECTION("Crossing edges without motion are in contact at the start; apart, not at all.") {
    expect_outcome(false, edge_vs_xaxis({0, -1, 0}, {0, 1, 0}, {0, -1, 0}, {0, 1, 0}),
                   CcdOutcome::kContactAtStart);
    expect_outcome(false, edge_vs_xaxis({0, -1, 0.5}, {0, 1, 0.5}, {0, -1, 0.5}, {0, 1, 0.5}),
                   CcdOutcome::kNoContact);
  }
}

TEST_CASE("The minimum separation reports approaches closer than it.", "[ccd]") {
  // A vertex comes down over the interior to height 1/4; an edge over the x axis likewise.
  const Motion vf = point_vs_triangle({0.25, 0.25, 1}, {0.25, 0.25, 0.25});
  const Motion ee = edge_vs_xaxis({0, -1, 1}, {0, 1, 1}, {0, -1, 0.25}, {0, 1, 0.25});
  SECTION("Without separation, nothing is reported.") {
    expect_outcome(true, vf, CcdOutcome::kNoContact);
    expect_outcome(false, ee, CcdOutcome::kNoContact);
  }
  SECTION("A separation of 1/8 (smaller than the closest approach) reports nothing.") {
    CcdOptions o;
    o.min_separation = 0.125;
    expect_outcome(true, vf, CcdOutcome::kNoContact, o);
    expect_outcome(false, ee, CcdOutcome::kNoContact, o);
  }
  SECTION("A separation of 1/2 is reached at t = 2/3 and reported no later.") {
    for (const auto& t : transforms()) {
      CAPTURE(t.name());
      CcdOptions o;
      o.min_separation = 0.5 * t.scale;
      for (bool is_vf : {true, false}) {
        const CcdResult r = run(is_vf, is_vf ? vf : ee, t, o);
        REQUIRE(r.outcome == CcdOutcome::kContact);
        CHECK(r.toi <= 2.0 / 3.0 + 1e-15);
        CHECK(r.toi >= 2.0 / 3.0 - 1e-3);
      }
    }
  }
  SECTION("Starting within the separation is a contact at the start.") {
    CcdOptions o;
    o.min_separation = 2.0;
    expect_outcome(true, vf, CcdOutcome::kContactAtStart, o);
    expect_outcome(false, ee, CcdOutcome::kContactAtStart, o);
  }
}

TEST_CASE("Non-finite input is reported as a contact, never as a proof of separation.", "[ccd]") {
  const Vec3d nan{std::nan(""), 0, 0};
  const Vec3d z{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0};
  CHECK(tetseg::vertex_face_ccd(nan, z, x, y, nan, z, x, y).hit());
  CHECK(tetseg::edge_edge_ccd(z, x, nan, y, z, x, nan, y).hit());
  CHECK(tetseg::vertex_face_ccd_filter(nan, z, x, y, nan, z, x, y));
  const Vec3d inf{INFINITY, 0, 0};
  CHECK(tetseg::edge_edge_ccd(z, x, inf, y, z, x, inf, y).hit());
}

TEST_CASE(
    "An infinite minimum separation reports every pair, and a negative or NaN one means zero.",
    "[ccd]") {
  const Motion far = point_vs_triangle({5, 5, 5}, {6, 6, 6});
  const Transform identity;
  CcdOptions o;
  o.min_separation = INFINITY;
  CHECK(run(true, far, identity, o).outcome == CcdOutcome::kContactAtStart);
  o.min_separation = -1.0;
  CHECK(run(true, far, identity, o).outcome == CcdOutcome::kNoContact);
  o.min_separation = std::nan("");
  CHECK(run(true, far, identity, o).outcome == CcdOutcome::kNoContact);
}

namespace {

/// A rotation (from a random unit quaternion), a scale and a translation, in double: the
/// rounding of the transformed coordinates moves the true time of impact by about
/// `resolution` (ulp of the translation over the scale), which bounds the checks below.
struct RigidTransform {
  double m[3][3];
  double scale;
  Vec3d shift;
  Vec3d operator()(const Vec3d& x) const {
    Vec3d y;
    for (std::size_t i = 0; i < 3; ++i)
      y[i] = shift[i] + scale * (m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2]);
    return y;
  }
  double resolution() const {
    return (std::max({std::fabs(shift[0]), std::fabs(shift[1]), std::fabs(shift[2])}) + scale) *
           0x1p-52 / scale;
  }
};

RigidTransform random_rigid(std::mt19937_64& rng, double scale, double shift) {
  std::normal_distribution<double> g;
  double q[4] = {g(rng), g(rng), g(rng), g(rng)};
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& c : q) c /= n;
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  RigidTransform t{{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                    {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                    {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}},
                   scale,
                   {shift, -0.5 * shift, 0.25 * shift}};
  return t;
}

}  // namespace

TEST_CASE("Rotated, scaled and far-translated motions keep their time of impact.", "[ccd]") {
  std::mt19937_64 rng(42);
  struct Named {
    bool vf;
    Motion m;
    double toi;  // < 0: no contact (clear by a margin of 1/8 of the size)
  };
  // Only transversal motions clear of the boundary by a margin: rounding the rotated coordinates
  // turns an exactly coplanar motion into a slightly non-coplanar one whose answer may legitimately
  // differ (the coplanar cases are checked under exact transforms above).
  const std::vector<Named> cases{
      {true, point_vs_triangle({0.25, 0.25, 0.75}, {0.25, 0.25, -0.25}), 0.75},
      {true, point_vs_triangle({0.125, 0.75, 0.75}, {0.125, 0.75, -0.25}), 0.75},
      {true, point_vs_triangle({0.625, 0.625, 0.75}, {0.625, 0.625, -0.25}), -1},
      {false, edge_vs_xaxis({0, -1, 0.75}, {0, 1, 0.75}, {0, -1, -0.25}, {0, 1, -0.25}), 0.75},
      {false,
       edge_vs_xaxis({1.125, -1, 0.75}, {1.125, 1, 0.75}, {1.125, -1, -0.25}, {1.125, 1, -0.25}),
       -1},
      {false, edge_vs_xaxis({2, 1, 0}, {3, 1, 0}, {2, -1, 0}, {3, -1, 0}), -1},
  };
  for (double scale : {1e-4, 1e-2, 1.0, 1e2, 1e4}) {
    for (double shift : {0.0, 1e3, 1e6}) {
      for (int k = 0; k < 8; ++k) {
        const RigidTransform t = random_rigid(rng, scale, shift);
        const double slack = 1e-6 + 64 * t.resolution();
        for (std::size_t i = 0; i < cases.size(); ++i) {
          CAPTURE(scale, shift, k, i);
          std::array<Vec3d, 4> y0, y1;
          for (std::size_t j = 0; j < 4; ++j) {
            y0[j] = t(cases[i].m.x0[j]);
            y1[j] = t(cases[i].m.x1[j]);
          }
          const CcdResult r =
              cases[i].vf
                  ? tetseg::vertex_face_ccd(y0[0], y0[1], y0[2], y0[3], y1[0], y1[1], y1[2], y1[3])
                  : tetseg::edge_edge_ccd(y0[0], y0[1], y0[2], y0[3], y1[0], y1[1], y1[2], y1[3]);
          if (cases[i].toi < 0) {
            CHECK_FALSE(r.hit());
          } else {
            REQUIRE(r.outcome == CcdOutcome::kContact);
            CHECK(r.toi <= cases[i].toi + slack);
            CHECK(r.toi >= cases[i].toi - slack);
          }
        }
      }
    }
  }
}
