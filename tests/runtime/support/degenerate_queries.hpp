#pragma once
// Random elementary CCD queries of the degenerate kinds simulator steps produce (docs/ccd.md,
// "Exact contacts at the speed of float"), scaled by 1e-4 .. 1e4 and offset by 1e6, with the
// test and the exact rational oracle (testing/include/tetseg/testing/exact_ccd.hpp) on them.

#include <array>
#include <cmath>
#include <random>
#include <utility>

#include "tetseg/runtime/ccd.hpp"
#include "tetseg/testing/exact_ccd.hpp"

namespace tetseg::test {

enum Family {
  kEndInPlane,       // all four end in one axis plane (touching at t = 1 when they meet)
  kSlideInPlane,     // all four in one axis plane for the whole step
  kStartInPlane,     // all four start in one axis plane, then move off it
  kGenericCrossing,  // ordinary motion through the plane region
  kNearPlaneAtEnd,   // in the plane at the start, within 1e-15 of it at the end
  kGrid,             // coordinates on a coarse grid: exact touching and collinear features
  kPartlyStill,      // some points do not move
  kFamilies
};

inline const char* const kFamilyNames[kFamilies] = {
    "end in plane", "slide in plane", "start in plane", "generic",
    "near plane",   "grid",           "partly still"};

struct Query {
  bool edge_edge;
  Family family;
  std::array<Vec3d, 8> x;  // four points at t = 0, then the same four at t = 1
};

/// Random queries of one family, in a box of size about 1 before scaling and offset; the
/// plane is orthogonal to a random axis, at 0 or at a random height.
inline Query make_query(std::mt19937_64& rng, Family family, bool edge_edge) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> grid(0, 3);
  std::uniform_int_distribution<int> axes(0, 2);
  const int axis = axes(rng);
  const double scale = std::pow(10.0, std::floor(unit(rng) * 9.0) - 4.0);
  const double offset = unit(rng) < 0.3 ? 1e6 : 0.0;
  const double plane = unit(rng) < 0.5 ? 0.0 : unit(rng);
  Query q{edge_edge, family, {}};
  for (int k = 0; k < 4; ++k) {
    Vec3d a{}, b{};
    if (family == kGrid) {
      for (int c = 0; c < 3; ++c) {
        a[c] = 0.5 * grid(rng);
        b[c] = 0.5 * grid(rng);
      }
    } else {
      a = {unit(rng), unit(rng), 0.1 * unit(rng)};
      b = {a[0] + 0.2 * (unit(rng) - 0.5), a[1] + 0.2 * (unit(rng) - 0.5), 0.0};
      switch (family) {
        case kSlideInPlane:
          a[2] = 0.0;
          break;
        case kStartInPlane:
          a[2] = 0.0, b[2] = 0.1 * unit(rng);
          break;
        case kGenericCrossing:
          b[2] = a[2] - 0.15 * unit(rng);
          break;
        case kNearPlaneAtEnd:
          a[2] = 0.0, b[2] = (unit(rng) - 0.5) * 1e-15;
          break;
        case kPartlyStill:
          b[2] = unit(rng) < 0.5 ? a[2] : 0.0;
          break;
        default:
          break;
      }
      a[2] += plane;
      b[2] += plane;
    }
    std::swap(a[2], a[axis]);
    std::swap(b[2], b[axis]);
    for (int c = 0; c < 3; ++c) {
      a[c] = a[c] * scale + offset;
      b[c] = b[c] * scale + offset;
    }
    q.x[k] = a;
    q.x[4 + k] = b;
  }
  return q;
}

inline CcdResult run(const Query& q) {
  const auto& x = q.x;
  return q.edge_edge ? tetseg::edge_edge_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7])
                     : tetseg::vertex_face_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
}

inline ExactCcd exact_result(const Query& q) {
  const auto& x = q.x;
  return q.edge_edge
             ? tetseg::test::exact_edge_edge(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7])
             : tetseg::test::exact_vertex_face(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
}

}  // namespace tetseg::test
