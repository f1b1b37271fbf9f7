// Structured tet meshes: hex grids split into Kuhn tets, and the thin shapes built from them.

#include "tetseg/preprocess/structured.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "tetseg/preprocess/names.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess {
namespace {

double orientation(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return detail::dot(detail::sub(b, a), detail::cross(detail::sub(c, a), detail::sub(d, a)));
}

/// A ring of nx x layers x layers hexes around the z axis (major radius 1), rotated by
/// `place` afterwards.
TetMesh torus(int around, int layers, const std::function<Vec3(const Vec3&)>& place) {
  const double side = layers * 2.0 * detail::kPi / around;
  return hex_grid(
      around, layers, layers,
      [&](int i, int j, int k) {
        const double angle = 2.0 * detail::kPi * i / around;
        const double r = 1.0 + side * (static_cast<double>(j) / layers - 0.5);
        const double z = side * (static_cast<double>(k) / layers - 0.5);
        return place(Vec3{r * std::cos(angle), r * std::sin(angle), z});
      },
      true);
}

}  // namespace

TetMesh hex_grid(int nx, int ny, int nz, const std::function<Vec3(int, int, int)>& map,
                 bool periodic_x) {
  if (nx < 1 || ny < 1 || nz < 1 || (periodic_x && nx < 3))
    throw std::invalid_argument("hex_grid: too few hexes");
  const int layers_x = periodic_x ? nx : nx + 1;
  auto id = [=](int i, int j, int k) {
    return static_cast<std::uint32_t>(((i % layers_x) * (ny + 1) + j) * (nz + 1) + k);
  };
  TetMesh m;
  m.nodes.reserve(static_cast<std::size_t>(layers_x) * (ny + 1) * (nz + 1));
  for (int i = 0; i < layers_x; ++i)
    for (int j = 0; j <= ny; ++j)
      for (int k = 0; k <= nz; ++k) m.nodes.push_back(map(i, j, k));
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  m.tets.reserve(static_cast<std::size_t>(nx) * ny * nz * 6);
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (const auto& p : perms) {
          int c[3] = {i, j, k};
          Tet t;
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[static_cast<std::size_t>(s + 1)] = id(c[0], c[1], c[2]);
          }
          if (orientation(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]) < 0)
            std::swap(t[2], t[3]);
          m.tets.push_back(t);
        }
  return m;
}

StructuredShape structured_shape_from_name(const std::string& name) {
  StructuredShape shape;
  if (!parse_name(name, shape))
    throw std::invalid_argument("unknown shape '" + name + "' (expected " +
                                name_list<StructuredShape>(", ") + ")");
  return shape;
}

TetMesh generate_structured(StructuredShape shape, const StructuredOptions& options) {
  const bool thick = shape == StructuredShape::kPlate || shape == StructuredShape::kTori;
  const int layers = options.layers > 0 ? options.layers : (thick ? 3 : 1);
  int n = options.resolution;
  if (n <= 0) n = shape == StructuredShape::kBar ? 45 : shape == StructuredShape::kTori ? 48 : 40;
  if (n < 2 || n > 1000) throw std::invalid_argument("resolution must lie in 2..1000");
  if (layers > 64) throw std::invalid_argument("layers must lie in 1..64");
  const double h = 1.0 / n;
  switch (shape) {
    case StructuredShape::kMat:
    case StructuredShape::kPlate:
      return hex_grid(n, n, layers, [h](int i, int j, int k) { return Vec3{i * h, j * h, k * h}; });
    case StructuredShape::kBar:
      return hex_grid(n, layers, layers, [h](int i, int j, int k) {
        return Vec3{i * h, j * h, k * h};
      });
    case StructuredShape::kTorus:
      if (n < 3) throw std::invalid_argument("a torus needs resolution >= 3");
      return torus(n, layers, [](const Vec3& p) { return p; });
    case StructuredShape::kTori: {
      // Half-diagonals of both tubes must stay below the distance 1 of the centre circles.
      const double side = layers * 2.0 * detail::kPi / n;
      if (n < 3 || side * std::sqrt(2.0) >= 0.9)
        throw std::invalid_argument("tubes of " + std::to_string(layers) +
                                    " layers at resolution " + std::to_string(n) +
                                    " would touch (raise the resolution or lower the layers)");
      TetMesh first = torus(n, layers, [](const Vec3& p) { return p; });
      const TetMesh second = torus(n, layers, [](const Vec3& p) {
        return Vec3{1.0 + p[0], p[2], p[1]};
      });
      const auto offset = static_cast<std::uint32_t>(first.nodes.size());
      first.nodes.insert(first.nodes.end(), second.nodes.begin(), second.nodes.end());
      for (Tet t : second.tets) {  // already wound positively by hex_grid after placing
        for (std::uint32_t& v : t) v += offset;
        first.tets.push_back(t);
      }
      return first;
    }
  }
  throw std::invalid_argument("unknown structured shape");
}

}  // namespace tetseg::preprocess
