#pragma once
// Deformations shared by the collider tests: random sine waves, and the mushroom's drooping
// rim.

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "tetseg/testing/synthetic_scenes.hpp"

namespace tetseg::test {

struct Waves {
  std::vector<std::array<double, 7>> w;  // k (3), phase, direction (3)
  double amplitude;
  /// Wave vector components uniform in [-wavenumber, wavenumber].
  Waves(unsigned seed, double amp, double wavenumber = 3.0) : amplitude(amp) {
    std::mt19937 rng(seed);
    auto u = [&] { return (rng() / 4294967296.0) * 2 - 1; };
    for (int i = 0; i < 4; ++i)
      w.push_back({wavenumber * u(), wavenumber * u(), wavenumber * u(), 3 * u(), u(), u(), u()});
  }
  P3 operator()(const P3& p, double t) const {
    P3 q = p;
    for (const auto& a : w) {
      const double s = std::sin(a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + a[3]);
      for (int k = 0; k < 3; ++k) q[k] += t * amplitude * s * a[4 + k];
    }
    return q;
  }
};

/// Step f of `steps` of a deformation `motion(p, t)`, t in [0, 1], of the surface's vertices:
/// their positions at the step's start into `x0` and at its end into `x1` (flat xyz).
template <class Motion>
void motion_step(const Surface& s, const Motion& motion, int f, int steps, std::vector<double>& x0,
                 std::vector<double>& x1) {
  x0.clear();
  x1.clear();
  for (const P3& p : s.verts) {
    const P3 a = motion(p, double(f) / steps), b = motion(p, double(f + 1) / steps);
    x0.insert(x0.end(), a.begin(), a.end());
    x1.insert(x1.end(), b.begin(), b.end());
  }
}

/// The mushroom's (synthetic_scenes.hpp) rim droops towards its conical base around the
/// rim-tip vertex nearest angle 0 (largest radius above the stem), along the cone's normal
/// turned by `slant` radians about z (a smooth bump, largest at the tip): the tip is the
/// first point to reach the base.
struct RimDroop {
  std::uint32_t tip_vertex = 0;
  P3 tip;
  double phi = 0, radius = 0, slant = 0;
  RimDroop(const Surface& mushroom, double slant_angle) : slant(slant_angle) {
    double best = -1;
    for (std::uint32_t v = 0; v < mushroom.verts.size(); ++v) {
      const P3& q = mushroom.verts[v];
      const double score = std::hypot(q[0], q[1]) + 0.01 * q[0];
      if (score > best && q[2] > 1.6) best = score, tip_vertex = v;
    }
    tip = mushroom.verts[tip_vertex];
    phi = std::atan2(tip[1], tip[0]);
    radius = std::hypot(tip[0], tip[1]);
  }
  P3 operator()(const P3& q, double t) const {
    const double r = std::hypot(q[0], q[1]);
    const double arc = radius * std::remainder(std::atan2(q[1], q[0]) - phi, 2 * M_PI);
    const double d2 = (r - radius) * (r - radius) + (q[2] - tip[2]) * (q[2] - tip[2]);
    const double w = std::exp(-arc * arc / 1.0 - d2 / 0.09);
    const double dr = -1.4 * t * w / std::sqrt(2.0), dz = dr;
    const double c = std::cos(phi + slant), sn = std::sin(phi + slant);
    return P3{q[0] + dr * c, q[1] + dr * sn, q[2] + dz};
  }
};

}  // namespace tetseg::test
