// The triangle-pair plane filter (runtime/src/plane_filter.hpp): its cached face plane gives
// bitwise the orientation cubic of classify.hpp, and a plane-separated triangle pair has no
// feature pair with four distinct nodes that the elementary tests (brute force's) find in contact.

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "../../runtime/src/plane_filter.hpp"
#include "tetseg/runtime/ccd.hpp"
#include "tetseg/runtime/classify.hpp"

using namespace tetseg;

namespace {

Vec3d at(const std::vector<double>& x, std::uint32_t n) {
  return {x[3 * n], x[3 * n + 1], x[3 * n + 2]};
}

bool has_node(const std::array<std::uint32_t, 3>& t, std::uint32_t n) {
  return t[0] == n || t[1] == n || t[2] == n;
}

// Brute force over the two triangles: every vertex-face pair (both ways) and edge-edge pair
// with four distinct nodes through the elementary tests.
bool any_feature_contact(const std::array<std::uint32_t, 3>& t1,
                         const std::array<std::uint32_t, 3>& t2, const std::vector<double>& x0,
                         const std::vector<double>& x1) {
  const CcdOptions opt;
  for (int dir = 0; dir < 2; ++dir) {
    const auto& p = dir == 0 ? t1 : t2;
    const auto& f = dir == 0 ? t2 : t1;
    for (std::uint32_t v : p) {
      if (has_node(f, v)) continue;
      if (vertex_face_ccd(at(x0, v), at(x0, f[0]), at(x0, f[1]), at(x0, f[2]), at(x1, v),
                          at(x1, f[0]), at(x1, f[1]), at(x1, f[2]), opt)
              .hit())
        return true;
    }
  }
  for (int i = 0; i < 3; ++i) {
    const std::uint32_t a = t1[i], b = t1[(i + 1) % 3];
    for (int j = 0; j < 3; ++j) {
      const std::uint32_t c = t2[j], d = t2[(j + 1) % 3];
      if (a == c || a == d || b == c || b == d) continue;
      if (edge_edge_ccd(at(x0, a), at(x0, b), at(x0, c), at(x0, d), at(x1, a), at(x1, b), at(x1, c),
                        at(x1, d), opt)
              .hit())
        return true;
    }
  }
  return false;
}

}  // namespace

TEST_CASE("A face plane computed once gives bitwise the orientation cubic of classify",
          "[plane-filter]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double scale : {1e-6, 1.0, 1e6}) {
    for (int trial = 0; trial < 2000; ++trial) {
      double p[8][3];
      for (auto& q : p)
        for (double& c : q) c = scale * u(rng);
      if (trial % 4 == 0)  // nearly coplanar point: the error bounds matter
        for (int k = 0; k < 3; ++k) p[3][k] = (p[0][k] + p[1][k] + p[2][k]) / 3;
      const FacePlane plane(p[0], p[1], p[2], p[4], p[5], p[6]);
      const BernsteinCubic ref =
          orientation_bernstein(p[0], p[3], p[1], p[2], p[4], p[7], p[5], p[6]);
      REQUIRE(plane.side(p[3], p[7]) == sign_of(ref));
      REQUIRE(plane.side(p[3], p[7]) ==
              classify_orientation(p[0], p[3], p[1], p[2], p[4], p[7], p[5], p[6]));
    }
  }
}

TEST_CASE("The static error bound gives bitwise the orientation cubic's sign", "[plane-filter]") {
  // Points in boxes of random shape (one axis often much thinner), some exactly or nearly
  // coplanar; the runtime's bound: StaticErr::of the extents of the box of all eight points.
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-12.0, 4.0);
  std::size_t decided = 0, trials = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    double axis[3];
    for (double& a : axis) a = std::pow(10.0, trial % 3 == 0 ? e(rng) : e(rng) / 4);
    double p[8][3];
    for (auto& q : p)
      for (int k = 0; k < 3; ++k) q[k] = axis[k] * u(rng) + (trial % 7 == 0 ? 1e3 : 0.0);
    if (trial % 4 == 0)  // nearly coplanar point
      for (int k = 0; k < 3; ++k) p[3][k] = (p[0][k] + p[1][k] + p[2][k]) / 3;
    if (trial % 5 == 0)  // coplanar at the start, integer coordinates: k0 is exactly 0
      for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < 3; ++i) p[i][k] = std::round(p[i][k] * 8);
        p[3][k] = p[0][k] + p[1][k] - p[2][k];
      }
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = hi[k] = p[0][k];
      for (const auto& q : p) {
        lo[k] = std::min(lo[k], q[k]);
        hi[k] = std::max(hi[k], q[k]);
      }
    }
    const double extent[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    const auto err = orientation_detail::StaticErr::of(extent);
    const BernsteinCubic ref =
        orientation_bernstein(p[0], p[3], p[1], p[2], p[4], p[7], p[5], p[6]);
    // The property the shortcut rests on: the static bounds dominate the computed ones.
    REQUIRE(err.err0 >= ref.err[0]);
    REQUIRE(err.err1 >= ref.err[1]);
    REQUIRE(err.err1 >= ref.err[2]);
    REQUIRE(err.err0 >= ref.err[3]);
    bool d = false;
    orientation_detail::static_sign(ref.k, err, d);
    decided += d ? 1 : 0;
    ++trials;
    const Orientation want = classify_orientation(p[0], p[3], p[1], p[2], p[4], p[7], p[5], p[6]);
    const FacePlane plane(p[0], p[1], p[2], p[4], p[5], p[6]);
    // The plane filters' form: the lanes of FacePlaneStatic, then the full cubic (FaceSides).
    const FacePlaneStatic fast = FacePlaneStatic::of(p[0], p[1], p[2], p[4], p[5], p[6]);
    bool fast_decided = false;
    const Orientation fast_side = fast.static_side(p[3], p[7], err, fast_decided);
    if (fast_decided) REQUIRE(fast_side == want);
    REQUIRE(fast_decided == d);  // the same coefficients as orientation_bernstein's
    const std::vector<double> x0 = {p[0][0], p[0][1], p[0][2], p[1][0], p[1][1], p[1][2],
                                    p[2][0], p[2][1], p[2][2], p[3][0], p[3][1], p[3][2]};
    const std::vector<double> x1 = {p[4][0], p[4][1], p[4][2], p[5][0], p[5][1], p[5][2],
                                    p[6][0], p[6][1], p[6][2], p[7][0], p[7][1], p[7][2]};
    const MovingTriangle face{{0, 1, 2}, x0.data(), x1.data(), &fast};
    FaceSides sides(face, &err);
    REQUIRE(sides.of(p[3], p[7]) == want);
    REQUIRE(plane.side(p[3], p[7]) == want);
    // Classification's form: detector o = p[3], triangle (p[0], p[1], p[2]).
    REQUIRE(orientation_of(p[3], p[0], p[1], p[2], p[7], p[4], p[5], p[6], err) ==
            classify_orientation(p[3], p[0], p[1], p[2], p[7], p[4], p[5], p[6]));
    // The static bound is the permanent of the extents' determinant (det_perm of their
    // minors), found without the minors: bitwise.
    {
      using namespace orientation_detail;
      const V3 ext{extent[0], extent[1], extent[2]};
      double unused, perm;
      det_perm(ext, minors(ext, ext), unused, perm);
      REQUIRE(err.err0 == kRelErr * perm + kAbsErr);
      REQUIRE(err.err1 == kRelErr * (perm + perm + perm) + kAbsErr);
    }
#if defined(TETSEG_HAVE_LANES2)
    // The feature filters' lanes (orientation_k2): bitwise orientation_bernstein's coefficients
    // of the same points.
    {
      orientation_detail::Lanes2 k03, k12;
      orientation_detail::orientation_k2(p[0], p[3], p[1], p[2], p[4], p[7], p[5], p[6], k03, k12);
      const double k[4] = {k03[0], k12[0], k12[1], k03[1]};
      for (int i = 0; i < 4; ++i) REQUIRE(std::memcmp(&k[i], &ref.k[i], sizeof(double)) == 0);
      // The plane filters' cached face: the same coefficients.
      orientation_detail::Lanes2 f03, f12;
      fast.coefficients(p[3], p[7], f03, f12);
      const double kf[4] = {f03[0], f12[0], f12[1], f03[1]};
      for (int i = 0; i < 4; ++i) REQUIRE(std::memcmp(&kf[i], &ref.k[i], sizeof(double)) == 0);
      bool d2 = false;
      const Orientation s2 = orientation_detail::static_sign(k03, k12, err, d2);
      bool d1 = false;
      const Orientation s1 = orientation_detail::static_sign(ref.k, err, d1);
      REQUIRE(d2 == d1);
      REQUIRE(s2 == s1);
    }
#endif
  }
  // The shortcut is taken, not bypassed (most random cubics are decided by it).
  CHECK(decided > trials / 2);
}

TEST_CASE("Plane-separated triangle pairs have no feature pair in contact (brute force)",
          "[plane-filter]") {
  // Triangle pairs sharing 0, 1 or 2 nodes, moving linearly so that many of them collide:
  // the second triangle is thrown through the first, or a neighbour folds over its shared
  // edge or vertex. Every pair the filter rejects must be free of contact for brute force,
  // and the filter must reject many pairs while others do touch (the test is not vacuous).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int separated = 0, touching = 0, touching_shared = 0;
  for (int shared = 0; shared <= 2; ++shared) {
    for (int trial = 0; trial < 3000; ++trial) {
      const std::uint32_t nodes = 6 - shared;
      std::vector<double> x0(3 * nodes), x1(3 * nodes);
      for (double& c : x0) c = u(rng);
      // Motion: small random jitter plus, for the second triangle's own nodes, a throw
      // through the first triangle's region (scaled by a random factor, often zero).
      const double throw_scale = trial % 3 == 0 ? 0.0 : 1.5 * u(rng);
      const std::array<double, 3> dir = {u(rng), u(rng), u(rng)};
      for (std::uint32_t n = 0; n < nodes; ++n) {
        for (int k = 0; k < 3; ++k) {
          double d = 0.3 * u(rng);
          if (n >= 3) d += throw_scale * dir[k];
          x1[3 * n + k] = x0[3 * n + k] + d;
        }
      }
      const std::array<std::uint32_t, 3> t1 = {0, 1, 2};
      std::array<std::uint32_t, 3> t2;
      for (int k = 0; k < 3; ++k)
        t2[k] =
            k < shared ? static_cast<std::uint32_t>(k) : static_cast<std::uint32_t>(3 + k - shared);
      if (trial % 2) std::swap(t2[0], t2[2]);  // either winding
      const bool sep =
          plane_separated({t1, x0.data(), x1.data()}, {t2, x0.data(), x1.data()}, true);
      // The runtime's form (static bound of the box of all nodes, FacePlaneStatic): the same.
      double lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        lo[k] = hi[k] = x0[k];
        for (std::uint32_t n = 0; n < nodes; ++n)
          for (const auto* x : {&x0, &x1}) {
            lo[k] = std::min(lo[k], (*x)[3 * n + k]);
            hi[k] = std::max(hi[k], (*x)[3 * n + k]);
          }
      }
      const double extent[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
      const auto err = orientation_detail::StaticErr::of(extent);
      REQUIRE(plane_separated({t1, x0.data(), x1.data()}, {t2, x0.data(), x1.data()}, true, &err) ==
              sep);
      const bool contact = any_feature_contact(t1, t2, x0, x1);
      CAPTURE(shared, trial);
      if (sep) REQUIRE_FALSE(contact);
      separated += sep;
      touching += contact;
      if (contact && shared > 0) ++touching_shared;
    }
  }
  CHECK(separated > 1500);
  CHECK(touching > 500);
  CHECK(touching_shared > 200);
}

TEST_CASE("shared_node_mask marks exactly the nodes of one triangle found in the other",
          "[plane-filter]") {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<std::uint32_t> id(0, 6);
  for (int trial = 0; trial < 5000; ++trial) {
    std::array<std::uint32_t, 3> q, f;
    for (auto& n : q) n = id(rng);
    for (auto& n : f) n = id(rng);
    if (trial % 3 == 0) q[trial % 2] = 0xffffffffu;  // large ids
    if (trial % 5 == 0) f[2] = 0xffffffffu;
    unsigned want = 0;
    for (unsigned i = 0; i < 3; ++i)
      if (has_node(f, q[i])) want |= 1u << i;
    CAPTURE(q[0], q[1], q[2], f[0], f[1], f[2]);
    REQUIRE(shared_node_mask(q, f) == want);
  }
}
