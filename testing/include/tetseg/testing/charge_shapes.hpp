#pragma once
// Closed, outward-oriented test surfaces for the charge tests and benchmark, generated here so
// they depend on nothing but the standard library.

#include <string>
#include <utility>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::test {

using preprocess::Tri;
using preprocess::TriangleMesh;
using preprocess::Vec3;

/// Geodesic sphere: each icosahedron face split into k*k triangles, vertices projected to the
/// sphere of `radius` about the origin. 20 k^2 triangles.
TriangleMesh icosphere(int k, double radius = 1.0);

/// Ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1: the unit geodesic sphere scaled per axis.
TriangleMesh ellipsoid(int k, double a, double b, double c);

/// Surface of revolution about the z axis. `profile` is a polyline of (r, z) points starting
/// and ending on the axis (r = 0); it is resampled by arc length with spacing about h and each
/// ring gets about 2 pi r / h vertices.
TriangleMesh revolve(const std::vector<std::pair<double, double>>& profile, double h);

/// Dumbbell along z: spheres of radius 0.5 centred at z = +-0.8 joined by a cylinder of
/// radius 0.2 (concave creases where the neck meets the bulbs, at |z| ~ 0.342).
TriangleMesh dumbbell(double h);

/// Chess pawn along z: flat base disc (r 0.5, z 0..0.12), a concave flare into a stem
/// (r 0.16 at z ~ 0.45), a collar (r 0.3 at z 0.75), a narrow neck (r 0.12 at z ~ 0.84)
/// and a head sphere (r 0.25 centred at z 1.05).
TriangleMesh pawn(double h);

/// z values of the pawn's concave regions: [lo, hi] bands.
std::vector<std::pair<double, double>> pawn_neck_bands();

/// 1-to-4 midpoint subdivision (flat: the new vertices stay on the old triangles).
TriangleMesh subdivide(const TriangleMesh& mesh);

/// Minimal OFF reader (triangles only; polygons are fanned). Throws std::runtime_error.
TriangleMesh read_off(const std::string& path);

/// Signed enclosed volume (positive for outward orientation).
double signed_volume(const TriangleMesh& mesh);

}  // namespace tetseg::test
