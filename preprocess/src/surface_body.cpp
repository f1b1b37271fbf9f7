// Surface bodies (build_surface_asset, docs/segmentation.md "Surface bodies"): an asset on the
// input surface as it is, no tets behind it. The clustering stages run on the closed
// components with points sampled inside them as detector candidates; each detector is then
// written as non-negative weights of surface vertices around it.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

#include "components.hpp"
#include "mesh_topology.hpp"
#include "part_stages.hpp"
#include "tetseg/format/asset_io.hpp"
#include "tetseg/preprocess/pipeline.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "validate_internal.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess {
namespace {

using detail::cross;
using detail::distance2;
using detail::dot;
using detail::sub;

constexpr std::uint32_t kUnset = 0xffffffffu;

/// The components of a surface (triangles joined through shared vertices), in order of their
/// smallest triangle id, and whether each is closed (every edge shared by two triangles).
struct SurfaceComponents {
  std::vector<std::vector<std::uint32_t>> triangles;  ///< per component, ascending ids
  std::vector<bool> closed;  ///< closed and wound outward (check_closed_components)
  std::size_t inward = 0;    ///< closed components wound inward (overlap-only)
};

std::string triangle_name(const TriangleMesh& mesh, std::size_t t) {
  const Tri& tri = mesh.triangles[t];
  return std::to_string(t) + " (" + std::to_string(tri[0]) + " " + std::to_string(tri[1]) + " " +
         std::to_string(tri[2]) + ")";
}

/// The checks every component passes (finite, in range, no zero-area triangle, edges of at
/// most two triangles, consistent orientation); returns the components.
SurfaceComponents check_triangles(const TriangleMesh& mesh, const std::string& file) {
  if (mesh.triangles.empty()) throw InputError(file, "surface has no triangles");
  const std::size_t n = mesh.vertices.size();
  detail::check_finite(mesh.vertices, file, "vertex");
  detail::check_triangle_indices(mesh, file);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Tri& tri = mesh.triangles[t];
    const Vec3& a = mesh.vertices[tri[0]];
    const Vec3& b = mesh.vertices[tri[1]];
    const Vec3& c = mesh.vertices[tri[2]];
    const double longest = std::max({distance2(a, b), distance2(b, c), distance2(a, c)});
    const double doubled_area = detail::norm(cross(sub(b, a), sub(c, a)));
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] ||
        !(doubled_area > 1e-12 * longest))
      throw InputError(file, "degenerate triangle " + triangle_name(mesh, t) +
                                 " (zero area or a repeated vertex); a surface body keeps the "
                                 "input's triangles, so it cannot drop it");
  }
  struct HalfEdge {
    std::uint32_t lo, hi, tri;
    bool forward;
  };
  std::vector<HalfEdge> half;
  half.reserve(3 * mesh.triangles.size());
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = mesh.triangles[t][k];
      const std::uint32_t b = mesh.triangles[t][(k + 1) % 3];
      half.push_back({std::min(a, b), std::max(a, b), t, a < b});
    }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return std::tie(x.lo, x.hi, x.tri) < std::tie(y.lo, y.hi, y.tri);
  });
  detail::UnionFind sets(static_cast<std::uint32_t>(n));
  for (const Tri& t : mesh.triangles) {
    sets.unite(t[0], t[1]);
    sets.unite(t[0], t[2]);
  }
  std::vector<char> open_root(n, 0);
  for (std::size_t i = 0; i < half.size();) {
    std::size_t j = i + 1;
    while (j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi) ++j;
    const std::string edge =
        "between vertices " + std::to_string(half[i].lo) + " and " + std::to_string(half[i].hi);
    if (j - i > 2)
      throw InputError(file, "surface has a non-manifold edge " + edge + " (shared by " +
                                 std::to_string(j - i) + " triangles)");
    if (j - i == 2 && half[i].forward == half[i + 1].forward)
      throw InputError(file, "surface is not consistently oriented: triangles " +
                                 std::to_string(half[i].tri) + " and " +
                                 std::to_string(half[i + 1].tri) +
                                 " run the same way along the "
                                 "edge " +
                                 edge);
    if (j - i == 1) open_root[sets.find(half[i].lo)] = 1;
    i = j;
  }
  SurfaceComponents out;
  std::vector<std::uint32_t> component_of_root(n, kUnset);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const std::uint32_t root = sets.find(mesh.triangles[t][0]);
    if (component_of_root[root] == kUnset) {
      component_of_root[root] = static_cast<std::uint32_t>(out.triangles.size());
      out.triangles.emplace_back();
      out.closed.push_back(!open_root[root]);
    }
    out.triangles[component_of_root[root]].push_back(t);
  }
  return out;
}

/// The closed components' own checks. A closed component wound inward (a shell whose solid is
/// outside, e.g. a container) has no inside to put detectors in: it is marked open here
/// (overlap-only, checked as open components are). The outward ones pass
/// validate_closed_surface (vertex-manifold, no self-intersection) and are not nested.
void check_closed_components(const TriangleMesh& mesh, SurfaceComponents& components,
                             const std::string& file) {
  TriangleMesh outward;
  outward.vertices = mesh.vertices;
  for (std::size_t c = 0; c < components.triangles.size(); ++c) {
    if (!components.closed[c]) continue;
    std::vector<Tri> own;
    for (std::uint32_t t : components.triangles[c]) own.push_back(mesh.triangles[t]);
    if (enclosed_volume(mesh.vertices, own) > 0.0) {
      outward.triangles.insert(outward.triangles.end(), own.begin(), own.end());
    } else {
      components.closed[c] = false;
      components.inward += 1;
    }
  }
  if (outward.triangles.empty()) return;
  detail::SurfaceCheck check;
  check.allow_components = true;
  detail::validate_closed_surface(outward, file, check, nullptr);
  detail::check_surface_not_nested(outward, file);
}

/// Inside test for one closed, outward component: the winding number along the +z ray from a
/// point, over the triangles bucketed by their xy box.
class InsideTest {
 public:
  InsideTest(const std::vector<Vec3>& points, const std::vector<Tri>& triangles)
      : m_points(points), m_triangles(triangles) {
    m_lo = m_hi = points[triangles.front()[0]];
    for (const Tri& t : triangles)
      for (std::uint32_t v : t)
        for (int k = 0; k < 3; ++k) {
          m_lo[k] = std::min(m_lo[k], points[v][k]);
          m_hi[k] = std::max(m_hi[k], points[v][k]);
        }
    m_cells = std::clamp<int>(static_cast<int>(std::sqrt(double(triangles.size())) / 2), 1, 512);
    m_size[0] = std::max((m_hi[0] - m_lo[0]) / m_cells, 1e-300);
    m_size[1] = std::max((m_hi[1] - m_lo[1]) / m_cells, 1e-300);
    std::vector<std::vector<std::uint32_t>> buckets(std::size_t(m_cells) * m_cells);
    for (std::uint32_t i = 0; i < triangles.size(); ++i) {
      Vec3 lo = points[triangles[i][0]], hi = lo;
      for (std::uint32_t v : triangles[i])
        for (int k = 0; k < 2; ++k) {
          lo[k] = std::min(lo[k], points[v][k]);
          hi[k] = std::max(hi[k], points[v][k]);
        }
      for (int x = cell(lo[0], 0); x <= cell(hi[0], 0); ++x)
        for (int y = cell(lo[1], 1); y <= cell(hi[1], 1); ++y)
          buckets[std::size_t(y) * m_cells + x].push_back(i);
    }
    m_start.push_back(0);
    for (const auto& b : buckets) {
      m_items.insert(m_items.end(), b.begin(), b.end());
      m_start.push_back(static_cast<std::uint32_t>(m_items.size()));
    }
  }

  const Vec3& lo() const { return m_lo; }
  const Vec3& hi() const { return m_hi; }

  /// True when the +z ray from `q` winds around it (crossings whose xy projection holds q
  /// strictly; a ray through an edge or vertex may miscount, which costs a candidate only).
  bool inside(const Vec3& q) const {
    for (int k = 0; k < 3; ++k)
      if (!(q[k] > m_lo[k] && q[k] < m_hi[k])) return false;
    const std::size_t b = std::size_t(cell(q[1], 1)) * m_cells + cell(q[0], 0);
    int winding = 0;
    for (std::uint32_t i = m_start[b]; i < m_start[b + 1]; ++i) {
      const Tri& t = m_triangles[m_items[i]];
      const Vec3& a = m_points[t[0]];
      const Vec3& p = m_points[t[1]];
      const Vec3& c = m_points[t[2]];
      const double wa = orient(p, c, q), wb = orient(c, a, q), wc = orient(a, p, q);
      if (!((wa > 0 && wb > 0 && wc > 0) || (wa < 0 && wb < 0 && wc < 0))) continue;
      const double total = wa + wb + wc;
      const double z = (wa * a[2] + wb * p[2] + wc * c[2]) / total;
      if (z > q[2]) winding += total > 0 ? 1 : -1;
    }
    return winding != 0;
  }

 private:
  static double orient(const Vec3& a, const Vec3& b, const Vec3& q) {
    return (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0]);
  }
  int cell(double x, int axis) const {
    const int c = static_cast<int>((x - m_lo[axis]) / m_size[axis]);
    return std::clamp(c, 0, m_cells - 1);
  }

  const std::vector<Vec3>& m_points;
  const std::vector<Tri>& m_triangles;
  Vec3 m_lo{}, m_hi{};
  int m_cells = 1;
  double m_size[2] = {1.0, 1.0};
  std::vector<std::uint32_t> m_start, m_items;
};

/// Grid points inside the component aimed at this many (docs/segmentation.md).
constexpr double kGridCandidates = 2048.0;

/// Detector candidates inside one closed component: a grid of about kGridCandidates points
/// inside it, and each vertex moved inward along its normal by a third of its mean edge length
/// when that point is inside. Deterministic.
std::vector<Vec3> interior_candidates(const std::vector<Vec3>& points,
                                      const std::vector<Tri>& triangles) {
  const InsideTest test(points, triangles);
  std::vector<Vec3> out;
  const double volume = enclosed_volume(points, triangles);
  const double spacing = std::cbrt(volume / kGridCandidates);
  // At most kMaxGridPoints points tested (a thin component lying diagonally in its box).
  constexpr double kMaxGridPoints = double(1 << 21);
  int count[3];
  double size = spacing;
  do {
    for (int k = 0; k < 3; ++k)
      count[k] = std::clamp(static_cast<int>((test.hi()[k] - test.lo()[k]) / size), 1, 256);
    size *= 1.25;
  } while (double(count[0]) * count[1] * count[2] > kMaxGridPoints);
  for (int i = 0; i < count[0]; ++i)
    for (int j = 0; j < count[1]; ++j)
      for (int l = 0; l < count[2]; ++l) {
        // Cell centres, nudged off the symmetric positions a mesh's vertices tend to share.
        const int index[3] = {i, j, l};
        Vec3 q;
        for (int k = 0; k < 3; ++k)
          q[k] = test.lo()[k] +
                 (test.hi()[k] - test.lo()[k]) * ((index[k] + 0.5 + 0.0137 * (k + 1)) / count[k]);
        if (test.inside(q)) out.push_back(q);
      }
  std::vector<Vec3> normal(points.size(), Vec3{0.0, 0.0, 0.0});
  std::vector<double> edge_sum(points.size(), 0.0);
  std::vector<std::uint32_t> edge_count(points.size(), 0);
  for (const Tri& t : triangles) {
    const Vec3 n = cross(sub(points[t[1]], points[t[0]]), sub(points[t[2]], points[t[0]]));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = t[k], w = t[(k + 1) % 3];
      for (int d = 0; d < 3; ++d) normal[v][d] += n[d];
      const double length = detail::distance_between(points[v], points[w]);
      edge_sum[v] += length;
      edge_sum[w] += length;
      edge_count[v] += 1;
      edge_count[w] += 1;
    }
  }
  for (std::uint32_t v = 0; v < points.size(); ++v) {
    const double length = detail::norm(normal[v]);
    if (edge_count[v] == 0 || !(length > 0.0)) continue;
    const double offset = edge_sum[v] / edge_count[v] / 3.0;
    Vec3 q;
    for (int d = 0; d < 3; ++d) q[d] = points[v][d] - offset * normal[v][d] / length;
    if (test.inside(q)) out.push_back(q);
  }
  return out;
}

/// Solves the 4x4 system `m x = r` by Gaussian elimination with partial pivoting; false when
/// singular.
bool solve4(double m[4][4], double r[4], double x[4]) {
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int row = col + 1; row < 4; ++row)
      if (std::fabs(m[row][col]) > std::fabs(m[pivot][col])) pivot = row;
    if (!(std::fabs(m[pivot][col]) > 1e-300)) return false;
    std::swap(m[pivot], m[col]);
    std::swap(r[pivot], r[col]);
    for (int row = col + 1; row < 4; ++row) {
      const double f = m[row][col] / m[col][col];
      for (int k = col; k < 4; ++k) m[row][k] -= f * m[col][k];
      r[row] -= f * r[col];
    }
  }
  for (int row = 3; row >= 0; --row) {
    double s = r[row];
    for (int k = row + 1; k < 4; ++k) s -= m[row][k] * x[k];
    x[row] = s / m[row][row];
  }
  return true;
}

/// The minimum-norm weights w >= 0 with sum w = 1 and sum w x_i = p over `points` (the most
/// even spread of p over them), by semismooth Newton on the dual: w = max(0, A^T lambda) with
/// columns a_i = ((x_i - p) / scale, 1). False when p is not inside the points' hull (no
/// convergence).
bool spread_weights(const std::vector<Vec3>& points, const Vec3& p, double scale,
                    std::vector<double>& weights) {
  const std::size_t n = points.size();
  std::vector<std::array<double, 4>> a(n);
  for (std::size_t i = 0; i < n; ++i)
    a[i] = {(points[i][0] - p[0]) / scale, (points[i][1] - p[1]) / scale,
            (points[i][2] - p[2]) / scale, 1.0};
  double lambda[4] = {0.0, 0.0, 0.0, 1.0 / static_cast<double>(n)};
  auto residual = [&](const double* l, double* f) {
    f[0] = f[1] = f[2] = 0.0;
    f[3] = -1.0;
    for (const auto& ai : a) {
      const double w = std::max(0.0, ai[0] * l[0] + ai[1] * l[1] + ai[2] * l[2] + ai[3] * l[3]);
      for (int k = 0; k < 4; ++k) f[k] += w * ai[k];
    }
    return std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2] + f[3] * f[3]);
  };
  double f[4];
  double norm_f = residual(lambda, f);
  for (int iteration = 0; iteration < 100 && norm_f > 1e-14; ++iteration) {
    double j[4][4] = {};
    for (const auto& ai : a) {
      if (!(ai[0] * lambda[0] + ai[1] * lambda[1] + ai[2] * lambda[2] + ai[3] * lambda[3] > 0))
        continue;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) j[r][c] += ai[r] * ai[c];
    }
    for (int r = 0; r < 4; ++r) j[r][r] += 1e-12;
    double rhs[4] = {-f[0], -f[1], -f[2], -f[3]};
    double step[4];
    if (!solve4(j, rhs, step)) return false;
    double t = 1.0;
    bool moved = false;
    while (t > 1e-12) {
      double trial[4], f_trial[4];
      for (int k = 0; k < 4; ++k) trial[k] = lambda[k] + t * step[k];
      const double norm_trial = residual(trial, f_trial);
      if (norm_trial < (1.0 - 1e-4 * t) * norm_f) {
        std::copy(trial, trial + 4, lambda);
        std::copy(f_trial, f_trial + 4, f);
        norm_f = norm_trial;
        moved = true;
        break;
      }
      t *= 0.5;
    }
    if (!moved) break;
  }
  if (!(norm_f <= 1e-10)) return false;
  weights.resize(n);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& ai = a[i];
    weights[i] = std::max(
        0.0, ai[0] * lambda[0] + ai[1] * lambda[1] + ai[2] * lambda[2] + ai[3] * lambda[3]);
    sum += weights[i];
  }
  if (!(sum > 0.0)) return false;
  for (double& w : weights) w /= sum;
  return true;
}

/// Fixed directions spread over the sphere (a Fibonacci lattice).
std::vector<Vec3> sphere_directions(int count) {
  std::vector<Vec3> out;
  const double golden = detail::kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    out.push_back({r * std::cos(golden * i), r * std::sin(golden * i), z});
  }
  return out;
}

/// Surface vertices adjacent through triangles (compressed rows).
struct VertexRings {
  std::vector<std::uint32_t> start, neighbours;
};

VertexRings vertex_rings(std::size_t vertex_count, const std::vector<Tri>& triangles) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const Tri& t : triangles)
    for (int k = 0; k < 3; ++k) {
      edges.emplace_back(t[k], t[(k + 1) % 3]);
      edges.emplace_back(t[(k + 1) % 3], t[k]);
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  VertexRings rings;
  rings.start.assign(vertex_count + 1, 0);
  for (const auto& e : edges) rings.start[e.first + 1] += 1;
  std::partial_sum(rings.start.begin(), rings.start.end(), rings.start.begin());
  for (const auto& e : edges) rings.neighbours.push_back(e.second);
  return rings;
}

/// A detector at `p` as weights of at most kSurfaceDetectorTerms surface vertices, chosen from
/// the cluster's vertices (`seed`) and, when p is not inside their hull, rings of vertices
/// around them (1, 2, 4, ... more rings until it is, or the component is exhausted): per fixed
/// direction from p the vertex best aligned with it (nearer on ties), then spread_weights. Empty
/// when none is found. Terms sorted by vertex id.
std::vector<format::DetectorTerm> detector_terms(const std::vector<Vec3>& points,
                                                 const VertexRings& rings,
                                                 std::vector<std::uint32_t> seed, const Vec3& p) {
  static const std::vector<Vec3> directions = sphere_directions(kSurfaceDetectorTerms);
  std::vector<char> taken(points.size(), 0);
  for (std::uint32_t v : seed) taken[v] = 1;
  std::vector<std::uint32_t> set = seed;
  std::vector<std::uint32_t> frontier = seed;
  std::size_t ring_count = 1;
  while (true) {
    double scale = 0.0;
    for (std::uint32_t v : set) scale = std::max(scale, distance2(points[v], p));
    scale = std::sqrt(scale);
    if (scale > 0.0) {
      std::vector<std::uint32_t> chosen;
      for (const Vec3& d : directions) {
        std::uint32_t best = kUnset;
        double best_cos = -2.0, best_distance = 0.0;
        for (std::uint32_t v : set) {
          const Vec3 e = sub(points[v], p);
          const double distance = detail::norm(e);
          if (!(distance > 0.0)) continue;
          const double c = dot(e, d) / distance;
          if (c > best_cos || (c == best_cos && distance < best_distance)) {
            best = v;
            best_cos = c;
            best_distance = distance;
          }
        }
        if (best != kUnset) chosen.push_back(best);
      }
      std::sort(chosen.begin(), chosen.end());
      chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
      std::vector<Vec3> chosen_points;
      for (std::uint32_t v : chosen) chosen_points.push_back(points[v]);
      std::vector<double> weights;
      if (chosen.size() >= 4 && spread_weights(chosen_points, p, scale, weights)) {
        std::vector<format::DetectorTerm> terms;
        for (std::size_t i = 0; i < chosen.size(); ++i)
          if (weights[i] > 0.0) terms.push_back({chosen[i], weights[i]});
        return terms;
      }
    }
    // As many rings again around the set as it has (doubling: a few rounds reach any part of
    // the component).
    const std::size_t added_before = set.size();
    for (std::size_t ring = 0; ring < std::max<std::size_t>(1, ring_count); ++ring) {
      std::vector<std::uint32_t> next;
      for (std::uint32_t v : frontier)
        for (std::uint32_t i = rings.start[v]; i < rings.start[v + 1]; ++i) {
          const std::uint32_t w = rings.neighbours[i];
          if (!taken[w]) {
            taken[w] = 1;
            next.push_back(w);
          }
        }
      if (next.empty()) break;
      set.insert(set.end(), next.begin(), next.end());
      frontier = std::move(next);
    }
    ring_count *= 2;
    if (set.size() == added_before) return {};
  }
}

}  // namespace

format::Asset build_surface_asset(const TriangleMesh& input, const std::string& source,
                                  const BuildOptions& options, BuildReport& report,
                                  const std::function<void(const StageReport&)>& on_stage) {
  if (detector_form_of(options) != format::DetectorForm::kSurfaceWeights)
    throw std::invalid_argument(
        "build_surface_asset builds detectors by weights (skin: carry_detectors_by_bones on "
        "its asset)");
  StageTimer timer(report, on_stage);
  const std::vector<Vec3>& points = input.vertices;
  const std::size_t vertex_count = points.size();
  report.nodes = static_cast<std::uint32_t>(vertex_count);
  report.surface_triangles = static_cast<std::uint32_t>(input.triangles.size());

  // Components: the solid ones (closed, with interior candidates) are clustered like a tet
  // mesh's surface; the others get one overlap-only cluster each.
  SurfaceComponents components;
  std::vector<Vec3> nodes = points;  // the vertices, then the interior candidates
  std::vector<detail::SurfacePart> parts;
  std::vector<std::uint32_t> solid_triangles;  // input ids of the parts' triangles, ascending
  std::vector<std::uint32_t> overlap_only_components;
  timer.run("surface", [&](std::string& summary) {
    components = check_triangles(input, source);
    check_closed_components(input, components, source);
    std::vector<char> in_part(input.triangles.size(), 0);
    std::vector<std::uint32_t> part_components;
    std::size_t candidates = 0;
    for (std::uint32_t c = 0; c < components.triangles.size(); ++c) {
      std::vector<Tri> own;
      for (std::uint32_t t : components.triangles[c]) own.push_back(input.triangles[t]);
      const std::vector<Vec3> inside =
          components.closed[c] ? interior_candidates(points, own) : std::vector<Vec3>{};
      if (inside.empty()) {
        overlap_only_components.push_back(c);
        continue;
      }
      detail::SurfacePart part;
      part.surface.triangles = std::move(own);
      for (const Tri& t : part.surface.triangles)
        part.surface.surface_nodes.insert(part.surface.surface_nodes.end(), t.begin(), t.end());
      std::sort(part.surface.surface_nodes.begin(), part.surface.surface_nodes.end());
      part.surface.surface_nodes.erase(
          std::unique(part.surface.surface_nodes.begin(), part.surface.surface_nodes.end()),
          part.surface.surface_nodes.end());
      for (const Vec3& q : inside) {
        part.surface.interior_nodes.push_back(static_cast<std::uint32_t>(nodes.size()));
        nodes.push_back(q);
      }
      candidates += inside.size();
      parts.push_back(std::move(part));
      part_components.push_back(c);
      for (std::uint32_t t : components.triangles[c]) in_part[t] = 1;
    }
    for (std::uint32_t t = 0; t < input.triangles.size(); ++t)
      if (in_part[t]) solid_triangles.push_back(t);
    // Part triangle ids are positions in solid_triangles.
    std::vector<std::uint32_t> position(input.triangles.size(), kUnset);
    for (std::uint32_t i = 0; i < solid_triangles.size(); ++i) position[solid_triangles[i]] = i;
    for (std::size_t p = 0; p < parts.size(); ++p)
      for (std::uint32_t t : components.triangles[part_components[p]])
        parts[p].triangles.push_back(position[t]);
    summary = std::to_string(input.triangles.size()) + " triangles, " +
              std::to_string(components.triangles.size()) + " components (" +
              std::to_string(overlap_only_components.size()) + " overlap-only, " +
              std::to_string(components.inward) + " closed inward), " + std::to_string(candidates) +
              " interior candidates";
    return 0;
  });
  report.components = static_cast<std::uint32_t>(components.triangles.size());
  report.interior_nodes = 0;  // the candidates are not nodes of the asset

  std::vector<Tri> solid;  // the parts' triangles, in solid_triangles order
  for (std::uint32_t t : solid_triangles) solid.push_back(input.triangles[t]);
  Segmentation solid_segmentation;
  if (!parts.empty())
    solid_segmentation =
        detail::segment_parts(nodes, parts, solid.size(), true, options, source, report, timer);

  // The whole surface's segmentation: solid clusters, then one cluster per other component,
  // renumbered by their smallest triangle id.
  Segmentation segmentation;
  std::vector<std::uint32_t> key(input.triangles.size());
  for (std::uint32_t i = 0; i < solid_triangles.size(); ++i)
    key[solid_triangles[i]] = solid_segmentation.triangle_cluster[i];
  for (std::size_t k = 0; k < overlap_only_components.size(); ++k)
    for (std::uint32_t t : components.triangles[overlap_only_components[k]])
      key[t] = solid_segmentation.cluster_count + static_cast<std::uint32_t>(k);
  std::vector<std::uint32_t> renumber(
      solid_segmentation.cluster_count + overlap_only_components.size(), kUnset);
  segmentation.triangle_cluster.resize(input.triangles.size());
  for (std::uint32_t t = 0; t < input.triangles.size(); ++t) {
    if (renumber[key[t]] == kUnset) renumber[key[t]] = segmentation.cluster_count++;
    segmentation.triangle_cluster[t] = renumber[key[t]];
  }
  segmentation.boundary_loops = solid_segmentation.boundary_loops;
  segmentation.boundary_lengths = solid_segmentation.boundary_lengths;
  segmentation.counts = solid_segmentation.counts;
  segmentation.counts.clusters = segmentation.cluster_count;
  report.segmentation = segmentation.counts;
  report.clusters = segmentation.cluster_count;
  report.boundaries = static_cast<std::uint32_t>(segmentation.boundary_loops.size());

  // Detector points chosen among the candidates, then written as surface weights.
  std::vector<DetectorChoice> detectors(segmentation.cluster_count);
  std::vector<std::vector<format::DetectorTerm>> terms(segmentation.cluster_count);
  timer.run("detectors", [&](std::string& summary) {
    std::vector<DetectorChoice> solid_detectors;
    if (!parts.empty()) {
      TetMesh candidates_only;  // no tets: the candidates are the interior nodes
      candidates_only.nodes = nodes;
      solid_detectors = detail::detectors_by_part(candidates_only, parts, solid_segmentation,
                                                  options.segmentation.detector,
                                                  options.segmentation.min_visibility);
    }
    const VertexRings rings = vertex_rings(vertex_count, input.triangles);
    std::vector<std::vector<std::uint32_t>> members(segmentation.cluster_count);
    for (std::uint32_t t = 0; t < input.triangles.size(); ++t)
      members[segmentation.triangle_cluster[t]].push_back(t);
    std::size_t weighted = 0, flagged = 0, term_count = 0;
    double worst = 1.0;
    std::vector<std::uint32_t> key_of_cluster(segmentation.cluster_count);
    for (std::uint32_t r = 0; r < renumber.size(); ++r) key_of_cluster[renumber[r]] = r;
    for (std::uint32_t c = 0; c < segmentation.cluster_count; ++c) {
      const std::uint32_t solid_cluster = key_of_cluster[c];
      DetectorChoice& d = detectors[c];
      d.triangle_count = static_cast<std::uint32_t>(members[c].size());
      d.overlap_only = true;
      if (solid_cluster < solid_segmentation.cluster_count) {
        const DetectorChoice& chosen = solid_detectors[solid_cluster];
        d.rest_positive_fraction = chosen.rest_positive_fraction;
        if (!chosen.overlap_only) {
          std::vector<std::uint32_t> seed;
          for (std::uint32_t t : members[c])
            seed.insert(seed.end(), input.triangles[t].begin(), input.triangles[t].end());
          std::sort(seed.begin(), seed.end());
          seed.erase(std::unique(seed.begin(), seed.end()), seed.end());
          terms[c] = detector_terms(points, rings, seed, chosen.position);
        }
        if (!terms[c].empty()) {
          d.position = format::weighted_detector_position(
              terms[c].data(), static_cast<std::uint32_t>(terms[c].size()), points.front().data());
          d.positive_triangles =
              count_positive_triangles(points, input.triangles, members[c], d.position);
          d.rest_positive_fraction =
              static_cast<float>(double(d.positive_triangles) / double(d.triangle_count));
          d.overlap_only =
              static_cast<double>(d.rest_positive_fraction) < options.segmentation.min_visibility;
        }
        if (d.overlap_only) terms[c].clear();
      }
      if (d.overlap_only) {
        ++flagged;
      } else {
        ++weighted;
        term_count += terms[c].size();
        worst = std::min<double>(worst, d.rest_positive_fraction);
      }
    }
    std::ostringstream text;
    text << detectors.size() << " detectors (" << weighted << " by weights, " << term_count
         << " terms), " << flagged << " overlap-only, lowest rest visibility " << worst;
    summary = text.str();
    return 0;
  });

  format::Asset asset;
  asset.node_count = static_cast<std::uint32_t>(vertex_count);
  asset.body_kind = format::BodyKind::kSurface;
  asset.detector_form = format::DetectorForm::kSurfaceWeights;
  detail::add_clusters(asset, points, input.triangles, segmentation, detectors, timer);
  for (std::uint32_t c = 0; c < segmentation.cluster_count; ++c) {
    format::Cluster& cluster = asset.clusters[c];
    cluster.detector = format::DetectorPoint::at_node(0);  // never read for this form
    cluster.detector_term_offset = static_cast<std::uint32_t>(asset.detector_terms.size());
    cluster.detector_term_count = static_cast<std::uint32_t>(terms[c].size());
    asset.detector_terms.insert(asset.detector_terms.end(), terms[c].begin(), terms[c].end());
    if (!terms[c].empty()) cluster.detector_rest = detectors[c].position;
  }
  if (options.keep_rest_positions) asset.rest_positions = points;
  BuildOptions used = options;
  used.detectors = format::DetectorForm::kSurfaceWeights;
  detail::set_provenance(asset, source, used, report);
  for (const DetectorChoice& detector : detectors)
    report.rest_positive_fraction.push_back(detector.rest_positive_fraction);
  std::string detail;
  if (format::validate(asset, &detail) != format::Status::kOk)
    throw std::runtime_error("internal error: built surface asset does not validate: " + detail);
  return asset;
}

}  // namespace tetseg::preprocess
