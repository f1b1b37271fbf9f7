// Closed-form potential of a uniformly charged triangle and the panel geometry (docs/charge.md).

#include "charge_potential.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <sstream>

#include "vec3_math.hpp"

namespace tetseg::preprocess::charge_detail {
namespace {

using detail::cross;
using detail::dot;
using detail::norm;
using detail::sub;

}  // namespace

double triangle_potential(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& r) {
  return TriangleKernel(a, b, c).potential(r);
}

TriangleKernel::TriangleKernel(const Vec3& a, const Vec3& b, const Vec3& c) {
  Vec3 n = cross(sub(b, a), sub(c, a));
  const double twice_area = norm(n);
  if (!(twice_area > 0.0)) return;
  m_valid = true;
  m_normal = {n[0] / twice_area, n[1] / twice_area, n[2] / twice_area};
  m_corner = a;
  const Vec3* v[3] = {&a, &b, &c};
  for (int i = 0; i < 3; ++i) {
    Edge& e = m_edge[i];
    e.start = *v[i];
    const Vec3 d = sub(*v[(i + 1) % 3], *v[i]);
    e.length = norm(d);
    e.dir = {d[0] / e.length, d[1] / e.length, d[2] / e.length};
    e.out = cross(e.dir, m_normal);
  }
}

double TriangleKernel::potential(const Vec3& r) const {
  if (!m_valid) return 0.0;
  const double d = dot(m_normal, sub(r, m_corner));
  const double ad = std::abs(d);
  // Offsets of the corners from r and their lengths: edge i runs from corner i to i + 1.
  const Vec3 rc[3] = {sub(m_edge[0].start, r), sub(m_edge[1].start, r), sub(m_edge[2].start, r)};
  const double dist[3] = {norm(rc[0]), norm(rc[1]), norm(rc[2])};
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    // Edge coordinates of the projection of r: dir and out are orthogonal to the normal, so
    // the offset from r to its projection drops out of the dot products.
    const Edge& e = m_edge[i];
    const double lm = dot(rc[i], e.dir);
    const double lp = lm + e.length;
    const double t = dot(rc[i], e.out);
    if (std::abs(t) < 1e-12 * e.length) continue;  // point on the edge line: the term vanishes
    const double rm = dist[i], rp = dist[(i + 1) % 3];
    const double log_term =
        lm < 0.0 ? std::log((rm - lm) / (rp - lp)) : std::log((rp + lp) / (rm + lm));
    sum += t * log_term;
  }
  if (ad > 0.0) {
    // The edges' angle terms add up to the solid angle the triangle subtends at r, taken in
    // one atan2 (van Oosterom & Strackee 1983) instead of one per edge.
    const double triple = dot(rc[0], cross(rc[1], rc[2]));
    const double denominator = dist[0] * dist[1] * dist[2] + dot(rc[0], rc[1]) * dist[2] +
                               dot(rc[0], rc[2]) * dist[1] + dot(rc[1], rc[2]) * dist[0];
    sum -= ad * 2.0 * std::atan2(std::abs(triple), denominator);
  }
  return sum;
}

double triangle_self_potential(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n_raw = cross(sub(b, a), sub(c, a));
  const double twice_area = norm(n_raw);
  if (!(twice_area > 0.0)) return 0.0;
  const Vec3 g = {(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0,
                  (a[2] + b[2] + c[2]) / 3.0};
  const Vec3* v[3] = {&a, &b, &c};
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    const Vec3& pm = *v[i];
    const Vec3& pp = *v[(i + 1) % 3];
    const Vec3 e = sub(pp, pm);
    const double len = norm(e);
    const double t = twice_area / (3.0 * len);  // centroid to edge line: 2A / (3 L)
    const double lp = dot(sub(pp, g), e) / len;
    const double lm = dot(sub(pm, g), e) / len;
    sum += t * (std::asinh(lp / t) - std::asinh(lm / t));
  }
  return sum;
}

PanelSet make_panels(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                     const std::string& file) {
  if (triangles.empty()) throw InputError(file, "the surface has no triangles");
  for (std::size_t p = 0; p < points.size(); ++p) {
    const Vec3& x = points[p];
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2])) {
      std::ostringstream msg;
      msg << "vertex " << p << " has a non-finite coordinate";
      throw InputError(file, msg.str());
    }
  }
  PanelSet s;
  const std::size_t n = triangles.size();
  s.corners.resize(n);
  s.centroid.resize(n);
  s.area.resize(n);
  s.diameter.resize(n);
  double max_edge = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    for (int k = 0; k < 3; ++k) {
      if (triangles[j][k] >= points.size()) {
        std::ostringstream msg;
        msg << "triangle " << j << " refers to vertex " << triangles[j][k] << " but there are "
            << points.size() << " vertices";
        throw InputError(file, msg.str());
      }
      s.corners[j][k] = points[triangles[j][k]];
    }
    const Vec3& a = s.corners[j][0];
    const Vec3& b = s.corners[j][1];
    const Vec3& c = s.corners[j][2];
    s.centroid[j] = {(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0,
                     (a[2] + b[2] + c[2]) / 3.0};
    s.area[j] = 0.5 * norm(cross(sub(b, a), sub(c, a)));
    s.diameter[j] = std::max({norm(sub(b, a)), norm(sub(c, b)), norm(sub(a, c))});
    max_edge = std::max(max_edge, s.diameter[j]);
  }
  for (std::size_t j = 0; j < n; ++j) {
    const double dj = s.diameter[j];
    if (detail::is_degenerate_panel(s.area[j], dj, max_edge)) {
      std::ostringstream msg;
      msg << "triangle " << j << " (vertices " << triangles[j][0] << ", " << triangles[j][1] << ", "
          << triangles[j][2] << ") is degenerate (area " << s.area[j] << ", longest edge " << dj
          << "); remove zero-area triangles (e.g. CGAL remove_degenerate_faces) first";
      throw InputError(file, msg.str());
    }
  }
  return s;
}

double matrix_entry(const PanelSet& panels, std::size_t i, std::size_t j) {
  if (i == j) {
    const auto& t = panels.corners[j];
    return triangle_self_potential(t[0], t[1], t[2]);
  }
  const Vec3 d = sub(panels.centroid[i], panels.centroid[j]);
  const double r2 = dot(d, d);
  const double near = kNearFactor * panels.diameter[j];
  if (r2 > near * near) return panels.area[j] / std::sqrt(r2);
  const double band = kQuadratureFactor * panels.diameter[j];
  if (r2 > band * band) {
    return triangle_potential_quadrature(panels.corners[j], panels.area[j], panels.centroid[i]);
  }
  const auto& t = panels.corners[j];
  return triangle_potential(t[0], t[1], t[2], panels.centroid[i]);
}

double triangle_potential_quadrature(const std::array<Vec3, 3>& corners, double area,
                                     const Vec3& r) {
  // Dunavant's degree-4 rule: two orbits of three points (barycentric (1 - 2 b, b, b)).
  constexpr double kB[2] = {0.091576213509771, 0.445948490915965};
  constexpr double kW[2] = {0.109951743655322, 0.223381589678011};
  // The six squared distances, then their inverse square roots two at a time (the same
  // correctly rounded operations as one at a time, so the same result, at half the
  // square roots' and divisions' issue slots), summed in the original order.
  double r2[6];
  for (int orbit = 0; orbit < 2; ++orbit) {
    const double b = kB[orbit], a = 1.0 - 2.0 * b;
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = corners[static_cast<std::size_t>(k)];
      const Vec3& q = corners[static_cast<std::size_t>((k + 1) % 3)];
      const Vec3& s = corners[static_cast<std::size_t>((k + 2) % 3)];
      const double x = a * p[0] + b * (q[0] + s[0]) - r[0];
      const double y = a * p[1] + b * (q[1] + s[1]) - r[1];
      const double z = a * p[2] + b * (q[2] + s[2]) - r[2];
      r2[orbit * 3 + k] = x * x + y * y + z * z;
    }
  }
  double inv[6];
#if defined(__SSE2__)
  const __m128d one = _mm_set1_pd(1.0);
  for (int k = 0; k < 6; k += 2) {
    _mm_storeu_pd(inv + k, _mm_div_pd(one, _mm_sqrt_pd(_mm_loadu_pd(r2 + k))));
  }
#else
  for (int k = 0; k < 6; ++k) inv[k] = 1.0 / std::sqrt(r2[k]);
#endif
  double sum = 0.0;
  for (int orbit = 0; orbit < 2; ++orbit) {
    double partial = 0.0;
    for (int k = 0; k < 3; ++k) partial += inv[orbit * 3 + k];
    sum += kW[orbit] * partial;
  }
  return area * sum;
}

}  // namespace tetseg::preprocess::charge_detail
