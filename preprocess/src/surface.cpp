// Boundary extraction and volumes. No CGAL here.

#include <algorithm>
#include <tuple>
#include <vector>

#include "tetseg/preprocess/surface.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess {
namespace {

// Faces of a positively oriented tet, wound so that the normal points away from the opposite
// vertex (index = the opposite vertex).
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

struct FaceRecord {
  std::array<std::uint32_t, 3> key;  // sorted vertex ids
  std::uint32_t tet;
  std::uint8_t local;
};

}  // namespace

Surface extract_surface(const TetMesh& mesh) {
  std::vector<FaceRecord> faces;
  faces.reserve(mesh.tets.size() * 4);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const Tet& tet = mesh.tets[t];
    for (std::uint8_t f = 0; f < 4; ++f) {
      std::array<std::uint32_t, 3> key = {tet[kFace[f][0]], tet[kFace[f][1]], tet[kFace[f][2]]};
      std::sort(key.begin(), key.end());
      faces.push_back({key, static_cast<std::uint32_t>(t), f});
    }
  }
  std::sort(faces.begin(), faces.end(), [](const FaceRecord& a, const FaceRecord& b) {
    return std::tie(a.key, a.tet, a.local) < std::tie(b.key, b.tet, b.local);
  });
  std::vector<std::pair<std::uint32_t, std::uint8_t>> boundary;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i == 1) boundary.emplace_back(faces[i].tet, faces[i].local);
    i = j;
  }
  std::sort(boundary.begin(), boundary.end());
  Surface surface;
  surface.triangles.reserve(boundary.size());
  std::vector<char> on_surface(mesh.nodes.size(), 0);
  for (const auto& [t, f] : boundary) {
    const Tet& tet = mesh.tets[t];
    const Tri tri = {tet[kFace[f][0]], tet[kFace[f][1]], tet[kFace[f][2]]};
    surface.triangles.push_back(tri);
    for (std::uint32_t v : tri)
      if (v < on_surface.size()) on_surface[v] = 1;
  }
  for (std::uint32_t v = 0; v < on_surface.size(); ++v) {
    if (on_surface[v]) {
      surface.surface_nodes.push_back(v);
    } else {
      surface.interior_nodes.push_back(v);
    }
  }
  return surface;
}

double enclosed_volume(const std::vector<Vec3>& points, const std::vector<Tri>& triangles) {
  // Divergence theorem with the centroid as origin (less cancellation than the world origin).
  Vec3 c = {0, 0, 0};
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) c[k] += p[k];
  if (!points.empty())
    for (int k = 0; k < 3; ++k) c[k] /= static_cast<double>(points.size());
  double sum = 0.0;
  for (const Tri& t : triangles) {
    if (t[0] >= points.size() || t[1] >= points.size() || t[2] >= points.size()) continue;
    const Vec3& a = points[t[0]];
    const Vec3& b = points[t[1]];
    const Vec3& d = points[t[2]];
    const double u[3] = {a[0] - c[0], a[1] - c[1], a[2] - c[2]};
    const double v[3] = {b[0] - c[0], b[1] - c[1], b[2] - c[2]};
    const double w[3] = {d[0] - c[0], d[1] - c[1], d[2] - c[2]};
    sum += u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
  }
  return sum / 6.0;
}

double total_tet_volume(const TetMesh& mesh) {
  double sum = 0.0;
  const std::size_t n = mesh.nodes.size();
  for (const Tet& t : mesh.tets) {
    if (t[0] >= n || t[1] >= n || t[2] >= n || t[3] >= n) continue;
    const Vec3& a = mesh.nodes[t[0]];
    const Vec3& b = mesh.nodes[t[1]];
    const Vec3& c = mesh.nodes[t[2]];
    const Vec3& d = mesh.nodes[t[3]];
    sum += detail::tet_det(a, b, c, d);
  }
  return sum / 6.0;
}

}  // namespace tetseg::preprocess
