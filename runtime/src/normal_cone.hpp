#pragma once
// Private data and maths of the collider's normal cones (collider_cone.cpp): ColliderMode::kCone, a
// baseline in the spirit of ICCD (Tang et al. 2009) over the kBvh mode's global BVH. The
// functions take any BVH (`ConeTree`); a per-cluster use (a "hybrid" mode) was measured and
// removed, docs/benchmarks.md. Not installed.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "tetseg/format/asset.hpp"

namespace tetseg {

/// Contour tests are skipped (node not culled) for nodes with more boundary edges than this.
inline constexpr std::uint32_t kMaxContourEdges = 256;
/// Leaves with more triangles than this get no cone (never culled).
inline constexpr std::uint32_t kMaxConeLeaf = 16;

/// One BVH whose nodes carry cones: `nodes[i]` has cone index `base + i`; leaf ranges index
/// `leaf` (global triangle ids), `leaf_count` entries.
struct ConeTree {
  const format::BvhNode* nodes = nullptr;
  const std::uint32_t* leaf = nullptr;
  std::uint32_t count = 0;
  std::uint32_t leaf_count = 0;
  std::uint32_t base = 0;
};

struct ConeData {
  bool topology_built = false;
  /// Sizes every per-node array for `node_count` nodes (all wide, no loop).
  void init(std::uint32_t node_count) {
    bnd_begin.assign(node_count, 0);
    bnd_end.assign(node_count, 0);
    bnd_edges.clear();
    loop_ok.assign(node_count, 0);
    axis.assign(std::size_t(node_count) * 3, 0.0);
    angle.assign(node_count, 4.0);
  }
  // Static, per global BVH node: its boundary edges (edges with exactly one incident
  // triangle in the node) and whether they form one simple closed loop of <= kMaxContourEdges.
  std::vector<std::uint32_t> bnd_begin, bnd_end;  // per node: range in bnd_edges
  std::vector<std::uint32_t> bnd_edges;           // edge ids
  std::vector<std::uint8_t> loop_ok;
  // Per step, per node: a cone containing the three Bernstein control normals of every
  // triangle of the node (axis unit vector, half-angle in radians; >= pi/2 means "wide").
  std::vector<double> axis;  // 3 per node
  std::vector<double> angle;
};

/// The cone maths of the kCone mode (collider_cone.cpp): small vectors, the smallest-angle cone
/// of unit vectors, signs of Bernstein quadratics.
namespace cone_math {

constexpr double kHalfPi = 1.5707963267948966;
constexpr double kWide = 4.0;  // any angle >= pi/2 means "no useful cone"
constexpr double kAnglePad = 1e-9;

struct V3 {
  double x, y, z;
};
inline V3 sub(const double* a, const double* b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double dot(const V3& a, const V3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline double norm(const V3& a) {
  return std::sqrt(dot(a, a));
}

/// Smallest-angle cone of unit vectors; returns the half-angle (kWide when degenerate).
inline double cone_of(const V3* v, int n, V3& axis) {
  V3 s{0, 0, 0};
  for (int i = 0; i < n; ++i) {
    s.x += v[i].x;
    s.y += v[i].y;
    s.z += v[i].z;
  }
  const double l = norm(s);
  if (!(l > 1e-12)) return kWide;
  axis = {s.x / l, s.y / l, s.z / l};
  double d = 1;  // acos is decreasing: one acos of the smallest dot product
  for (int i = 0; i < n; ++i) d = std::min(d, dot(axis, v[i]));
  return std::acos(std::clamp(d, -1.0, 1.0)) + kAnglePad;
}

struct P2 {
  double x, y;
};
inline double cross2(const P2& a, const P2& b) {
  return a.x * b.y - a.y * b.x;
}
inline double dot2(const P2& a, const P2& b) {
  return a.x * b.x + a.y * b.y;
}
inline P2 sub2(const P2& a, const P2& b) {
  return {a.x - b.x, a.y - b.y};
}
inline double l1(const P2& a) {
  return std::fabs(a.x) + std::fabs(a.y);
}

/// Sign over t in [0,1] of q(t) = f(u(t), w(t)) for f = cross or dot of linearly moving
/// vectors u, w: +1 / -1 when all three Bernstein coefficients are strictly signed with margin,
/// else 0.
inline int bernstein_sign(const P2& u0, const P2& u1, const P2& w0, const P2& w1, bool use_dot) {
  double c[3];
  if (use_dot) {
    c[0] = dot2(u0, w0);
    c[1] = 0.5 * (dot2(u0, w1) + dot2(u1, w0));
    c[2] = dot2(u1, w1);
  } else {
    c[0] = cross2(u0, w0);
    c[1] = 0.5 * (cross2(u0, w1) + cross2(u1, w0));
    c[2] = cross2(u1, w1);
  }
  const double tol = 1e-10 * (l1(u0) + l1(u1)) * (l1(w0) + l1(w1));
  if (c[0] > tol && c[1] > tol && c[2] > tol) return 1;
  if (c[0] < -tol && c[1] < -tol && c[2] < -tol) return -1;
  return 0;
}

}  // namespace cone_math

}  // namespace tetseg
