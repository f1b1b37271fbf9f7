// Generated closed surfaces for the charge tests and benchmark (see charge_shapes.hpp).

#include "tetseg/testing/charge_shapes.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace tetseg::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void flip_if_inward(TriangleMesh& mesh) {
  if (signed_volume(mesh) < 0.0) {
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  }
}

double smooth_max(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::max(a, b) + h * h * k * 0.25;
}

std::vector<std::pair<double, double>> sample_profile(double (*radius)(double), double z0,
                                                      double z1, int samples) {
  std::vector<std::pair<double, double>> p;
  p.emplace_back(0.0, z0);
  for (int i = 0; i <= samples; ++i) {
    const double z = z0 + (z1 - z0) * i / samples;
    p.emplace_back(radius(z), z);
  }
  p.emplace_back(0.0, z1);
  return p;
}

double dumbbell_radius(double z) {
  const double s = 0.25 - (std::abs(z) - 0.8) * (std::abs(z) - 0.8);
  const double bulb = s > 0.0 ? std::sqrt(s) : 0.0;
  const double neck = std::abs(z) <= 0.8 ? 0.2 : 0.0;
  return std::max(bulb, neck);
}

double pawn_radius(double z) {
  const double base = z <= 0.12 ? 0.5 : 0.0;
  // Stem: flares concavely out of the base, tapers to 0.16, then into the collar.
  const double stem =
      (z > 0.12 && z < 0.8) ? 0.16 + 0.12 * std::exp(-(z - 0.12) / 0.06) - 0.03 * (z - 0.12) : 0.0;
  const double cz = (z - 0.75) / 0.04;
  const double collar = std::abs(cz) < 1.0 ? 0.3 * std::sqrt(1.0 - cz * cz) : 0.0;
  const double neck = (z >= 0.75 && z <= 0.9) ? 0.12 : 0.0;
  const double hs = 0.0625 - (z - 1.05) * (z - 1.05);
  const double head = hs > 0.0 ? std::sqrt(hs) : 0.0;
  return smooth_max(smooth_max(smooth_max(smooth_max(base, stem, 0.02), collar, 0.02), neck, 0.02),
                    head, 0.02);
}

}  // namespace

double signed_volume(const TriangleMesh& mesh) {
  double v = 0.0;
  for (const auto& t : mesh.triangles) {
    v += dot(mesh.vertices[t[0]], cross(mesh.vertices[t[1]], mesh.vertices[t[2]]));
  }
  return v / 6.0;
}

TriangleMesh icosphere(int k, double radius) {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  const std::vector<Vec3> ico = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                                 {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                                 {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  const std::vector<Tri> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                  {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                  {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                  {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  TriangleMesh mesh;
  std::map<Vec3, std::uint32_t> ids;
  auto vertex = [&](const Vec3& p) {
    auto it = ids.find(p);
    if (it != ids.end()) return it->second;
    const auto id = static_cast<std::uint32_t>(mesh.vertices.size());
    ids.emplace(p, id);
    mesh.vertices.push_back(p);
    return id;
  };
  for (const auto& f : faces) {
    const Vec3& a = ico[f[0]];
    const Vec3& b = ico[f[1]];
    const Vec3& c = ico[f[2]];
    std::vector<std::vector<std::uint32_t>> grid(static_cast<std::size_t>(k) + 1);
    for (int i = 0; i <= k; ++i) {
      for (int j = 0; i + j <= k; ++j) {
        const double wa = k - i - j, wb = i, wc = j;
        Vec3 p;
        for (int e = 0; e < 3; ++e) p[e] = (a[e] * wa + b[e] * wb + c[e] * wc) / k;
        grid[static_cast<std::size_t>(i)].push_back(vertex(p));
      }
    }
    for (int i = 0; i < k; ++i) {
      for (int j = 0; i + j < k; ++j) {
        const auto& g0 = grid[static_cast<std::size_t>(i)];
        const auto& g1 = grid[static_cast<std::size_t>(i) + 1];
        mesh.triangles.push_back({g0[static_cast<std::size_t>(j)], g1[static_cast<std::size_t>(j)],
                                  g0[static_cast<std::size_t>(j) + 1]});
        if (i + j < k - 1) {
          mesh.triangles.push_back({g1[static_cast<std::size_t>(j)],
                                    g1[static_cast<std::size_t>(j) + 1],
                                    g0[static_cast<std::size_t>(j) + 1]});
        }
      }
    }
  }
  for (auto& p : mesh.vertices) {
    const double len = std::sqrt(dot(p, p));
    for (auto& e : p) e *= radius / len;
  }
  flip_if_inward(mesh);
  return mesh;
}

TriangleMesh ellipsoid(int k, double a, double b, double c) {
  TriangleMesh mesh = icosphere(k, 1.0);
  for (auto& p : mesh.vertices) p = {p[0] * a, p[1] * b, p[2] * c};
  return mesh;
}

TriangleMesh revolve(const std::vector<std::pair<double, double>>& profile, double h) {
  // Resample the profile by arc length.
  std::vector<double> s(profile.size(), 0.0);
  for (std::size_t i = 1; i < profile.size(); ++i) {
    s[i] = s[i - 1] + std::hypot(profile[i].first - profile[i - 1].first,
                                 profile[i].second - profile[i - 1].second);
  }
  const int m = std::max(2, static_cast<int>(std::ceil(s.back() / h)));
  std::vector<std::pair<double, double>> rings;
  std::size_t seg = 1;
  for (int i = 0; i <= m; ++i) {
    const double target = s.back() * i / m;
    while (seg + 1 < s.size() && s[seg] < target) ++seg;
    const double len = s[seg] - s[seg - 1];
    const double t = len > 0.0 ? std::clamp((target - s[seg - 1]) / len, 0.0, 1.0) : 0.0;
    const double r = profile[seg - 1].first + t * (profile[seg].first - profile[seg - 1].first);
    const double z = profile[seg - 1].second + t * (profile[seg].second - profile[seg - 1].second);
    rings.emplace_back(i == 0 || i == m ? 0.0 : r, z);
  }
  TriangleMesh mesh;
  std::vector<std::vector<std::uint32_t>> ring_ids;
  for (std::size_t i = 0; i < rings.size(); ++i) {
    const double r = rings[i].first;
    const int count = r <= 0.0 ? 1 : std::max(3, static_cast<int>(std::lround(2 * kPi * r / h)));
    std::vector<std::uint32_t> ids;
    const double offset = (i % 2) * 0.5;
    for (int j = 0; j < count; ++j) {
      const double a = 2 * kPi * (j + offset) / count;
      ids.push_back(static_cast<std::uint32_t>(mesh.vertices.size()));
      mesh.vertices.push_back({r * std::cos(a), r * std::sin(a), rings[i].second});
    }
    ring_ids.push_back(ids);
  }
  for (std::size_t i = 0; i + 1 < ring_ids.size(); ++i) {
    const auto& lo = ring_ids[i];
    const auto& hi = ring_ids[i + 1];
    const std::size_t na = lo.size(), nb = hi.size();
    const double oa = (i % 2) * 0.5, ob = ((i + 1) % 2) * 0.5;
    if (na == 1) {
      for (std::size_t j = 0; j < nb; ++j)
        mesh.triangles.push_back({lo[0], hi[(j + 1) % nb], hi[j]});
      continue;
    }
    if (nb == 1) {
      for (std::size_t j = 0; j < na; ++j)
        mesh.triangles.push_back({lo[j], lo[(j + 1) % na], hi[0]});
      continue;
    }
    std::size_t a = 0, b = 0;
    while (a < na || b < nb) {
      const double next_a = (a + 1 + oa) / static_cast<double>(na);
      const double next_b = (b + 1 + ob) / static_cast<double>(nb);
      if (b == nb || (a < na && next_a <= next_b)) {
        mesh.triangles.push_back({lo[a % na], lo[(a + 1) % na], hi[b % nb]});
        ++a;
      } else {
        mesh.triangles.push_back({lo[a % na], hi[(b + 1) % nb], hi[b % nb]});
        ++b;
      }
    }
  }
  flip_if_inward(mesh);
  return mesh;
}

TriangleMesh dumbbell(double h) {
  return revolve(sample_profile(dumbbell_radius, -1.3, 1.3, 20000), h);
}

TriangleMesh pawn(double h) {
  return revolve(sample_profile(pawn_radius, 0.0, 1.3, 20000), h);
}

std::vector<std::pair<double, double>> pawn_neck_bands() {
  return {{0.10, 0.30}, {0.68, 0.86}};
}

TriangleMesh subdivide(const TriangleMesh& mesh) {
  TriangleMesh out;
  out.vertices = mesh.vertices;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
  auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    const auto key = std::minmax(a, b);
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    const auto id = static_cast<std::uint32_t>(out.vertices.size());
    const Vec3& p = mesh.vertices[a];
    const Vec3& q = mesh.vertices[b];
    out.vertices.push_back({0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])});
    mid.emplace(key, id);
    return id;
  };
  for (const auto& t : mesh.triangles) {
    const std::uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]),
                        ca = midpoint(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({ab, t[1], bc});
    out.triangles.push_back({ca, bc, t[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

TriangleMesh read_off(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::vector<std::string> tokens;
  std::string line;
  auto next_line = [&](std::istringstream& ls) {
    while (std::getline(in, line)) {
      const auto hash = line.find('#');
      if (hash != std::string::npos) line.erase(hash);
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      ls.clear();
      ls.str(line);
      return true;
    }
    return false;
  };
  std::istringstream ls;
  if (!next_line(ls)) throw std::runtime_error(path + ": empty");
  std::string magic;
  ls >> magic;
  if (magic.find("OFF") == std::string::npos) throw std::runtime_error(path + ": not OFF");
  std::size_t nv = 0, nf = 0, ne = 0;
  if (!(ls >> nv)) {
    if (!next_line(ls)) throw std::runtime_error(path + ": truncated");
    ls >> nv;
  }
  ls >> nf >> ne;
  TriangleMesh mesh;
  for (std::size_t i = 0; i < nv; ++i) {
    Vec3 p{};
    if (!next_line(ls) || !(ls >> p[0] >> p[1] >> p[2])) {
      throw std::runtime_error(path + ": bad vertex");
    }
    mesh.vertices.push_back(p);
  }
  for (std::size_t i = 0; i < nf; ++i) {
    std::size_t k = 0;
    if (!next_line(ls) || !(ls >> k) || k < 3) throw std::runtime_error(path + ": bad face");
    std::vector<std::uint32_t> v(k);
    for (auto& e : v) {
      if (!(ls >> e) || e >= nv) throw std::runtime_error(path + ": bad face index");
    }
    for (std::size_t j = 1; j + 1 < k; ++j) mesh.triangles.push_back({v[0], v[j], v[j + 1]});
  }
  return mesh;
}

}  // namespace tetseg::test
