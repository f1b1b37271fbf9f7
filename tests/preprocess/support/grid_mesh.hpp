#pragma once
// Kuhn-triangulated grids of cubes: small, valid tet meshes built in code for the import,
// surface and validation tests (preprocess::hex_grid).

#include <cstdint>
#include <functional>
#include <utility>

#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/preprocess/structured.hpp"

namespace tetseg::test {

using preprocess::TetMesh;
using preprocess::Vec3;

/// det[b-a, c-a, d-a]: six times the signed volume of tet (a, b, c, d).
inline double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/// nx x ny x nz cubes, 6 tets each (Kuhn), node (i, j, k) placed at map(i, j, k) (node id
/// (i * (ny + 1) + j) * (nz + 1) + k); tets are oriented positively after mapping.
inline TetMesh kuhn_grid(int nx, int ny, int nz, const std::function<Vec3(int, int, int)>& map) {
  return preprocess::hex_grid(nx, ny, nz, map);
}

/// An n^3 grid of unit cubes.
inline TetMesh cube_grid(int n) {
  return kuhn_grid(n, n, n, [](int i, int j, int k) {
    return Vec3{double(i), double(j), double(k)};
  });
}

}  // namespace tetseg::test
