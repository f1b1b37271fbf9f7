#pragma once
/// \file
/// The scene oracle's feature pairs (scene_oracle.hpp) decided by the exact rational CCD
/// oracle (exact_ccd.hpp) instead of the runtime's elementary tests: the exact contacts of a
/// step, against which the floating-point answers are held (nothing missed, no time of impact
/// after the exact one). Tests only (GMP).

#include <vector>

#include "tetseg/testing/exact_ccd.hpp"
#include "tetseg/testing/scene_oracle.hpp"

namespace tetseg::test {

/// Every feature pair of the step that touches at some t in [0, 1] (exactly), named as the
/// runtime names them; `toi` is the exact first contact time rounded up. Sorted by
/// `contact_less`.
inline std::vector<Contact> scene_exact_contacts(const std::vector<OracleBody>& bodies) {
  auto answer = [](const ExactCcd& r) { return OracleAnswer{r.hit, r.at_start, r.toi_upper}; };
  return scene_contacts(
      bodies,
      [&](const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& p1,
          const Vec3d& a1, const Vec3d& b1,
          const Vec3d& c1) { return answer(exact_vertex_face(p0, a0, b0, c0, p1, a1, b1, c1)); },
      [&](const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0, const Vec3d& a1,
          const Vec3d& b1, const Vec3d& c1,
          const Vec3d& d1) { return answer(exact_edge_edge(a0, b0, c0, d0, a1, b1, c1, d1)); });
}

}  // namespace tetseg::test
