// CGAL Mesh_3 on implicit functions: the procedural shapes (sphere, ellipsoid, dumbbell, pawn).
// Slow to compile; keep changes rare.

#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_triangulation_3.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "cgal_mesh.hpp"
#include "mesh3_extract.hpp"

namespace tetseg::preprocess::detail {
namespace {

using cgal::Kernel;
using FT = Kernel::FT;
using cgal::Point;
using Domain = CGAL::Labeled_mesh_domain_3<Kernel>;

/// Polynomial smooth minimum (blend width k): C1, equal to min where |a - b| >= k.
double smooth_min(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

/// Signed distance of a 2D rounded box (half extents hx, hz, corner radius r) in the (r, z)
/// half-plane of a solid of revolution.
double round_box(double rr, double z, double hx, double hz, double r) {
  const double qx = std::abs(rr) - hx + r;
  const double qz = std::abs(z) - hz + r;
  const double ox = std::max(qx, 0.0);
  const double oz = std::max(qz, 0.0);
  return std::sqrt(ox * ox + oz * oz) + std::min(std::max(qx, qz), 0.0) - r;
}

/// Signed distance of a round cone (sphere r1 at height 0, sphere r2 at height h, on the axis).
double round_cone(double rr, double z, double r1, double r2, double h) {
  const double b = (r1 - r2) / h;
  const double a = std::sqrt(1.0 - b * b);
  const double k = -b * rr + a * z;
  if (k < 0.0) return std::sqrt(rr * rr + z * z) - r1;
  if (k > a * h) return std::sqrt(rr * rr + (z - h) * (z - h)) - r2;
  return rr * a + z * b - r1;
}

/// Chess pawn of revolution about z, from z = 0 (base) to about 1.65 (top of the head).
double pawn(const Point& p) {
  const double x = CGAL::to_double(p.x());
  const double y = CGAL::to_double(p.y());
  const double z = CGAL::to_double(p.z());
  const double r = std::sqrt(x * x + y * y);
  constexpr double kBlend = 0.06;
  const double base = round_box(r, z - 0.12, 0.5, 0.12, 0.05);
  const double tier = round_box(r, z - 0.28, 0.38, 0.06, 0.04);
  const double stem = round_cone(r, z - 0.3, 0.26, 0.13, 0.75);
  const double collar = round_box(r, z - 1.08, 0.27, 0.035, 0.035);
  const double head = std::sqrt(r * r + (z - 1.38) * (z - 1.38)) - 0.27;
  double d = smooth_min(base, tier, kBlend);
  d = smooth_min(d, stem, kBlend);
  d = smooth_min(d, collar, kBlend);
  return smooth_min(d, head, kBlend);
}

/// Two balls (radius 0.5 at x = +-0.8) joined by a neck (radius 0.2), smoothly blended so the
/// neck is concave and smooth.
double dumbbell(const Point& p) {
  const double x = CGAL::to_double(p.x());
  const double y = CGAL::to_double(p.y());
  const double z = CGAL::to_double(p.z());
  const double yz = y * y + z * z;
  const double left = std::sqrt((x + 0.8) * (x + 0.8) + yz) - 0.5;
  const double right = std::sqrt((x - 0.8) * (x - 0.8) + yz) - 0.5;
  const double cx = std::clamp(x, -0.8, 0.8);
  const double neck = std::sqrt((x - cx) * (x - cx) + yz) - 0.2;
  constexpr double kBlend = 0.15;
  return smooth_min(smooth_min(left, right, kBlend), neck, kBlend);
}

}  // namespace

}  // namespace tetseg::preprocess::detail

namespace tetseg::preprocess {

// Here because only the Mesh_3 units are compiled with CGAL_LINKED_WITH_TBB.
bool meshing_threads_available() {
#if defined(CGAL_LINKED_WITH_TBB)
  return true;
#else
  return false;
#endif
}

}  // namespace tetseg::preprocess

namespace tetseg::preprocess::detail {

TetMesh mesh_implicit_shape(Shape shape, const ShapeOptions& o, const Mesh3Criteria& criteria) {
  std::function<FT(const Point&)> f;
  Point center(0, 0, 0);
  double bound = 1.0;
  switch (shape) {
    case Shape::kSphere: {
      const double radius = o.radius;
      f = [radius](const Point& p) {
        return std::sqrt(CGAL::to_double(CGAL::squared_distance(p, Point(0, 0, 0)))) - radius;
      };
      bound = 1.2 * radius;
      break;
    }
    case Shape::kEllipsoid: {
      const double a = o.axes[0];
      const double b = o.axes[1];
      const double c = o.axes[2];
      const double scale = std::min({a, b, c});
      f = [a, b, c, scale](const Point& p) {
        const double x = CGAL::to_double(p.x()) / a;
        const double y = CGAL::to_double(p.y()) / b;
        const double z = CGAL::to_double(p.z()) / c;
        return (std::sqrt(x * x + y * y + z * z) - 1.0) * scale;
      };
      bound = 1.2 * std::max({a, b, c});
      break;
    }
    case Shape::kDumbbell:
      f = dumbbell;
      bound = 1.5;
      break;
    case Shape::kPawn:
      f = pawn;
      center = Point(0, 0, 0.85);
      bound = 1.1;
      break;
  }
  CGAL::Random rng(0);
  namespace params = CGAL::parameters;
  const Domain domain = Domain::create_implicit_mesh_domain(
      f, Kernel::Sphere_3(center, bound * bound), params::relative_error_bound = 1e-6,
      params::p_rng = &rng);
  return mesh_domain(domain, criteria);
}

}  // namespace tetseg::preprocess::detail
