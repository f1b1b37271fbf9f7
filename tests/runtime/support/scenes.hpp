#pragma once
// The synthetic scenes several collider tests share: a sphere (1 or 2 clusters), a dumbbell
// and a pawn, cut along z with detector nodes on the axis.

#include <cstdint>
#include <vector>

#include "tetseg/testing/synthetic_scenes.hpp"

namespace tetseg::test {

inline Scene sphere_scene(int clusters) {
  const Surface s = sphere(1.0, 20, 11);
  if (clusters == 1)
    return make_scene(s, std::vector<std::uint32_t>(s.tris.size(), 0), {{0.3, 0.1, 0.05}});
  return make_axial_scene(s, {0.0}, {-0.45, 0.45});
}

inline Scene dumbbell_scene() {
  return make_axial_scene(dumbbell(16, 26), {-0.6, 0.6}, {-1.6, 0.0, 1.6});
}

inline Scene pawn_scene() {
  return make_axial_scene(pawn(16, 30), {1.0, 2.6}, {0.4, 1.6, 3.3});
}

}  // namespace tetseg::test
