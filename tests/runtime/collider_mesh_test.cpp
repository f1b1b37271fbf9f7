// The collider against brute force on random smooth deformations of real meshes (CGAL demo
// meshes unpacked into the build tree; skipped when absent, tetseg/testing/test_data.hpp).

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "runtime/support/compare.hpp"
#include "runtime/support/off.hpp"

using namespace tetseg;
using namespace tetseg::test;

TEST_CASE("Radial-view culling matches brute force on deformed real meshes",
          "[collider][rvbc][mesh]") {
  const std::string name = GENERATE(as<std::string>{}, "eight", "anchor", "joint");
  const unsigned seed = GENERATE(11u, 12u);
  CAPTURE(name, seed);
  Surface s;
  if (!read_demo_surface(name, s)) return;
  const Scene scene = slab_scene(s, 5);
  const double size = bounding_diagonal(s);
  std::mt19937 rng(seed);
  auto u = [&] { return (rng() / 4294967296.0) * 2 - 1; };
  std::vector<std::array<double, 7>> waves;
  for (int i = 0; i < 4; ++i)
    waves.push_back({6 * u() / size, 6 * u() / size, 6 * u() / size, 3 * u(), u(), u(), u()});
  const auto frames = make_frames(scene, 10, [&](const P3& p, double t) {
    P3 q = p;
    for (const auto& w : waves) {
      const double sn = std::sin(w[0] * p[0] + w[1] * p[1] + w[2] * p[2] + w[3]);
      for (int k = 0; k < 3; ++k) q[k] += t * 0.2 * size * sn * w[4 + k];
    }
    return q;
  });
  const SequenceReport rep = compare_with_oracle(scene, frames);
  CHECK(rep.contact_frames == 1);  // every sequence reaches a contact
  CHECK(rep.rvbc_tests <= rep.brute_tests);
}
