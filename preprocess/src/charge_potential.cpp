// Closed-form potential of a uniformly charged triangle and the panel geometry (docs/charge.md).

#include "charge_potential.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tetseg::preprocess::charge_detail {
namespace {

inline Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}

}  // namespace

double triangle_potential(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& r) {
  Vec3 n = cross(sub(b, a), sub(c, a));
  const double twice_area = norm(n);
  if (!(twice_area > 0.0)) return 0.0;
  n = {n[0] / twice_area, n[1] / twice_area, n[2] / twice_area};
  const double d = dot(n, sub(r, a));
  const double ad = std::abs(d);
  const Vec3 rho = {r[0] - d * n[0], r[1] - d * n[1], r[2] - d * n[2]};
  const Vec3* v[3] = {&a, &b, &c};
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    const Vec3& pm = *v[i];
    const Vec3& pp = *v[(i + 1) % 3];
    const Vec3 e = sub(pp, pm);
    const double len = norm(e);
    const Vec3 l = {e[0] / len, e[1] / len, e[2] / len};
    const Vec3 u = cross(l, n);
    const Vec3 to_m = sub(pm, rho);
    const Vec3 to_p = sub(pp, rho);
    const double lp = dot(to_p, l);
    const double lm = dot(to_m, l);
    const double t = dot(to_m, u);
    if (std::abs(t) < 1e-12 * len) continue;  // point on the edge line: the term vanishes
    const double r0sq = t * t + d * d;
    const double rp = std::sqrt(lp * lp + r0sq);
    const double rm = std::sqrt(lm * lm + r0sq);
    const double log_term =
        lm < 0.0 ? std::log((rm - lm) / (rp - lp)) : std::log((rp + lp) / (rm + lm));
    sum += t * log_term;
    if (ad > 0.0) {
      sum -= ad * (std::atan2(t * lp, r0sq + ad * rp) - std::atan2(t * lm, r0sq + ad * rm));
    }
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
    if (!(s.area[j] > 1e-12 * max_edge * max_edge) || !(s.area[j] > 1e-10 * dj * dj)) {
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
  const auto& t = panels.corners[j];
  return triangle_potential(t[0], t[1], t[2], panels.centroid[i]);
}

}  // namespace tetseg::preprocess::charge_detail
