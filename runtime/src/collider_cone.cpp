// ColliderMode::kCone: continuous normal cones and contour tests on the global BVH, a
// baseline in the spirit of ICCD (Tang et al. 2009). docs/runtime.md, "Normal-cone mode".
// The cone maths (cones of unit vectors, Bernstein signs): normal_cone.hpp.
//
// Soundness. A node's self-test (all feature pairs inside the node's surface patch) is skipped
// when, for one unit axis u and every t in [0,1]:
//  (1) every triangle normal n(t) satisfies n(t).u > 0. n(t) = (1-t)^2 n0 + 2t(1-t) nm + t^2 n1
//      (quadratic Bernstein form; n0, n1 the end normals, nm the mixed control normal) lies in
//      the convex cone of its three control normals, so a cone of half-angle < pi/2 around u
//      containing all control normals of the node's triangles proves it;
//  (2) the patch is a manifold with exactly one boundary loop (static topology), and that loop
//      projected onto the plane orthogonal to u stays a simple closed curve.
// Then the projection is an orientation-preserving local homeomorphism whose boundary image
// is a simple curve, so each point of the plane has at most one preimage (the count equals
// the winding number of the boundary image): the patch is embedded at every t and no two
// distinct points of it touch, i.e. no feature pair inside it (four distinct nodes) makes
// contact. Pairs across nodes are traversed as in the kBvh mode (triangle pairs sharing a
// node skipped there, their orphan feature pairs tested every step: docs/runtime.md, "Adjacent
// triangle pairs"), so the same elementary tests find every contact.
// (2) is checked conservatively per pair of boundary edges: non-adjacent edges must have
// disjoint swept 2D boxes or be separated by the line of one of them for the whole step
// (quadratic Bernstein coefficients of the side test with a strict sign); adjacent edges must
// never fold onto each other (strict side sign, or a strictly negative dot product). Floating
// point: strict signs need a margin of 1e-10 relative to the magnitudes involved, cone angles
// are padded by 1e-9 rad per merge. Any doubt keeps the node's self-test.

#include <algorithm>
#include <cmath>

#include "collider_impl.hpp"
#include "normal_cone.hpp"

namespace tetseg {

using namespace cone_math;

void Collider::Impl::build_cone_topology(ConeData& cd, const ConeTree& tree,
                                         std::vector<std::uint32_t>& pos) {
  // pos: tri_count entries, kNone outside this tree; restored to kNone on return.
  const std::uint32_t n = tree.count;
  const format::BvhNode* nodes = tree.nodes;
  std::vector<std::uint32_t> begin(n), end(n);
  for (std::uint32_t i = 0; i < tree.leaf_count; ++i) pos[tree.leaf[i]] = i;
  for (std::uint32_t i = n; i-- > 0;) {
    const format::BvhNode& nd = nodes[i];
    if (nd.count > 0) {
      begin[i] = nd.first;
      end[i] = nd.first + nd.count;
    } else {
      begin[i] = std::min(begin[nd.first], begin[nd.second]);
      end[i] = std::max(end[nd.first], end[nd.second]);
    }
  }
  std::vector<std::uint32_t> local, verts;
  for (std::uint32_t i = 0; i < n; ++i) {
    local.clear();
    bool manifold = true;
    for (std::uint32_t k = begin[i]; k < end[i] && manifold; ++k) {
      for (std::uint32_t e : topo->tri_edges[tree.leaf[k]]) {
        std::uint32_t inside = 0;
        for (std::uint32_t j = topo->et_offset[e]; j < topo->et_offset[e + 1]; ++j)
          inside += pos[topo->et_list[j]] >= begin[i] && pos[topo->et_list[j]] < end[i];
        if (inside == 1) local.push_back(e);
        if (inside > 2) manifold = false;
      }
    }
    bool ok = manifold && local.size() >= 3 && local.size() <= kMaxContourEdges;
    if (ok) {
      // Every boundary vertex on exactly two boundary edges, and one cycle through all edges.
      verts.clear();
      for (std::uint32_t e : local) {
        verts.push_back(topo->edges[e][0]);
        verts.push_back(topo->edges[e][1]);
      }
      std::sort(verts.begin(), verts.end());
      for (std::size_t v = 0; v < verts.size() && ok; v += 2)
        ok = v + 1 < verts.size() && verts[v] == verts[v + 1] &&
             (v + 2 >= verts.size() || verts[v + 2] != verts[v]);
    }
    if (ok) {
      std::size_t walked = 1;
      std::uint32_t prev = local[0], at = topo->edges[local[0]][1];
      const std::uint32_t start = topo->edges[local[0]][0];
      while (at != start && walked <= local.size()) {
        std::uint32_t next = kNone;
        for (std::uint32_t e : local)
          if (e != prev && (topo->edges[e][0] == at || topo->edges[e][1] == at)) next = e;
        if (next == kNone) break;
        at = topo->edges[next][0] == at ? topo->edges[next][1] : topo->edges[next][0];
        prev = next;
        ++walked;
      }
      ok = at == start && walked == local.size();
    }
    const std::uint32_t g = tree.base + i;
    cd.loop_ok[g] = ok ? 1 : 0;
    cd.bnd_begin[g] = static_cast<std::uint32_t>(cd.bnd_edges.size());
    if (ok) cd.bnd_edges.insert(cd.bnd_edges.end(), local.begin(), local.end());
    cd.bnd_end[g] = static_cast<std::uint32_t>(cd.bnd_edges.size());
  }
  for (std::uint32_t i = 0; i < tree.leaf_count; ++i) pos[tree.leaf[i]] = kNone;
}

void Collider::Impl::build_global_cones() {
  cone.init(gbvh.count);
  std::vector<std::uint32_t> pos(tri_count, kNone);
  build_cone_topology(cone, ConeTree{gbvh.nodes.data(), gbvh.leaf.data(), gbvh.count, tri_count, 0},
                      pos);
  cone.topology_built = true;
}

void Collider::Impl::update_cones() noexcept {
  if (!cone.topology_built) {
    try {
      build_global_cones();  // only when the asset has no rest positions (allocates once)
    } catch (...) {
      return;  // angles stay wide: nothing is culled
    }
  }
  update_cone_tree(cone, ConeTree{gbvh.nodes.data(), gbvh.leaf.data(), gbvh.count, tri_count, 0});
}

void Collider::Impl::update_cone_tree(ConeData& cd, const ConeTree& tree) noexcept {
  for (std::uint32_t i = tree.count; i-- > 0;) {
    const format::BvhNode& nd = tree.nodes[i];
    V3 axis{0, 0, 1};
    double angle = kWide;
    if (nd.count > 0) {
      // Leaf: cone of all control normals of its triangles.
      V3 normals[3 * kMaxConeLeaf];
      int m = 0;
      bool degenerate = nd.count > kMaxConeLeaf;
      for (std::uint32_t k = 0; k < nd.count && !degenerate; ++k) {
        const auto& t = tris[tree.leaf[nd.first + k]];
        const V3 u0 = sub(pos0(t[1]), pos0(t[0])), w0 = sub(pos0(t[2]), pos0(t[0]));
        const V3 u1 = sub(pos1(t[1]), pos1(t[0])), w1 = sub(pos1(t[2]), pos1(t[0]));
        const V3 a = cross(u0, w1), b = cross(u1, w0);
        const V3 c[3] = {cross(u0, w0),
                         {0.5 * (a.x + b.x), 0.5 * (a.y + b.y), 0.5 * (a.z + b.z)},
                         cross(u1, w1)};
        for (const V3& v : c) {
          const double l = norm(v);
          if (!(l > 0)) {
            degenerate = true;
            break;
          }
          normals[m++] = {v.x / l, v.y / l, v.z / l};
        }
      }
      if (!degenerate) angle = cone_of(normals, m, axis);
    } else {
      const std::size_t c1 = tree.base + nd.first, c2 = tree.base + nd.second;
      const double a1 = cd.angle[c1], a2 = cd.angle[c2];
      if (a1 < kHalfPi && a2 < kHalfPi) {
        const double* p = &cd.axis[c1 * 3];
        const double* q = &cd.axis[c2 * 3];
        const V3 u1{p[0], p[1], p[2]}, u2{q[0], q[1], q[2]};
        const double phi = std::acos(std::clamp(dot(u1, u2), -1.0, 1.0));
        if (phi + a2 <= a1) {
          axis = u1;
          angle = a1 + kAnglePad;
        } else if (phi + a1 <= a2) {
          axis = u2;
          angle = a2 + kAnglePad;
        } else {
          angle = 0.5 * (phi + a1 + a2) + kAnglePad;
          if (angle < kHalfPi && phi > 1e-12) {
            // Rotate u1 towards u2 by (angle - a1) in their plane.
            const double s = (angle - a1) / phi;
            const double w1 = std::sin((1 - s) * phi) / std::sin(phi),
                         w2 = std::sin(s * phi) / std::sin(phi);
            V3 r{w1 * u1.x + w2 * u2.x, w1 * u1.y + w2 * u2.y, w1 * u1.z + w2 * u2.z};
            const double l = norm(r);
            if (l > 0) {
              axis = {r.x / l, r.y / l, r.z / l};
              angle += 1e-9;
            } else {
              angle = kWide;
            }
          } else if (angle < kHalfPi) {
            axis = u1;
          }
        }
      }
    }
    if (!(angle < kHalfPi)) angle = kWide;
    const std::size_t g = tree.base + i;
    cd.angle[g] = angle;
    cd.axis[g * 3 + 0] = axis.x;
    cd.axis[g * 3 + 1] = axis.y;
    cd.axis[g * 3 + 2] = axis.z;
  }
}

bool Collider::Impl::cone_self_free(const ConeData& cd, std::uint32_t node) const noexcept {
  if (!cd.topology_built || node >= cd.angle.size()) return false;
  if (!(cd.angle[node] < kHalfPi - 1e-6) || !cd.loop_ok[node]) return false;
  const double* ax = &cd.axis[std::size_t(node) * 3];
  const V3 u{ax[0], ax[1], ax[2]};
  // Orthonormal basis of the projection plane.
  const V3 pick = std::fabs(u.x) < 0.6 ? V3{1, 0, 0} : V3{0, 1, 0};
  V3 e1 = cross(u, pick);
  const double l = norm(e1);
  e1 = {e1.x / l, e1.y / l, e1.z / l};
  const V3 e2 = cross(u, e1);
  auto project = [&](const double* p) {
    return P2{p[0] * e1.x + p[1] * e1.y + p[2] * e1.z, p[0] * e2.x + p[1] * e2.y + p[2] * e2.z};
  };
  const std::uint32_t first = cd.bnd_begin[node], last = cd.bnd_end[node];
  const std::uint32_t k = last - first;
  // Projected end points at t = 0 and t = 1, and swept 2D boxes, of every boundary edge.
  P2 p0[kMaxContourEdges][2], p1[kMaxContourEdges][2];
  double box[kMaxContourEdges][4];
  for (std::uint32_t i = 0; i < k; ++i) {
    const auto& e = topo->edges[cd.bnd_edges[first + i]];
    for (int s = 0; s < 2; ++s) {
      p0[i][s] = project(pos0(e[s]));
      p1[i][s] = project(pos1(e[s]));
    }
    box[i][0] = std::min({p0[i][0].x, p0[i][1].x, p1[i][0].x, p1[i][1].x});
    box[i][1] = std::max({p0[i][0].x, p0[i][1].x, p1[i][0].x, p1[i][1].x});
    box[i][2] = std::min({p0[i][0].y, p0[i][1].y, p1[i][0].y, p1[i][1].y});
    box[i][3] = std::max({p0[i][0].y, p0[i][1].y, p1[i][0].y, p1[i][1].y});
  }
  // Side of moving point (c0 -> c1) against moving line (a -> b): sign over the whole step.
  auto side = [](const P2& a0, const P2& b0, const P2& c0, const P2& a1, const P2& b1,
                 const P2& c1) {
    return bernstein_sign(sub2(b0, a0), sub2(b1, a1), sub2(c0, a0), sub2(c1, a1), false);
  };
  for (std::uint32_t i = 0; i < k; ++i) {
    const auto& ei = topo->edges[cd.bnd_edges[first + i]];
    for (std::uint32_t j = i + 1; j < k; ++j) {
      const auto& ej = topo->edges[cd.bnd_edges[first + j]];
      int si = -1, sj = -1;  // shared vertex slots
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
          if (ei[a] == ej[b]) {
            si = a;
            sj = b;
          }
      if (si >= 0) {
        // Adjacent: v shared, a on edge i, b on edge j; they must never fold onto each other.
        const P2 v0 = p0[i][si], v1 = p1[i][si];
        const P2 a0 = p0[i][1 - si], a1 = p1[i][1 - si];
        const P2 b0 = p0[j][1 - sj], b1 = p1[j][1 - sj];
        if (side(v0, a0, b0, v1, a1, b1) != 0) continue;
        if (bernstein_sign(sub2(a0, v0), sub2(a1, v1), sub2(b0, v0), sub2(b1, v1), true) < 0)
          continue;
        return false;
      }
      if (box[i][0] > box[j][1] || box[j][0] > box[i][1] || box[i][2] > box[j][3] ||
          box[j][2] > box[i][3])
        continue;
      // Separated by the line of edge i or of edge j during the whole step.
      const int c = side(p0[i][0], p0[i][1], p0[j][0], p1[i][0], p1[i][1], p1[j][0]);
      if (c != 0 && c == side(p0[i][0], p0[i][1], p0[j][1], p1[i][0], p1[i][1], p1[j][1])) continue;
      const int d = side(p0[j][0], p0[j][1], p0[i][0], p1[j][0], p1[j][1], p1[i][0]);
      if (d != 0 && d == side(p0[j][0], p0[j][1], p0[i][1], p1[j][0], p1[j][1], p1[i][1])) continue;
      return false;
    }
  }
  return true;
}

}  // namespace tetseg
