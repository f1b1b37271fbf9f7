// The whole-surface BVH (median split, built once without allocation into storage reserved
// at construction) and the static rest-intersection check.

#include <algorithm>
#include <cmath>

#include "collider_impl.hpp"
#include "tetseg/runtime/median_bvh.hpp"

namespace tetseg {

void WholeSurfaceBvh::reserve(std::uint32_t tri_count) {
  const std::size_t cap = tri_count == 0 ? 1 : 2 * std::size_t(tri_count) - 1;
  nodes.resize(cap);
  leaf.resize(tri_count);
  centroid.resize(std::size_t(tri_count) * 3);
  build_stack.resize(kMedianBvhStack);
  box.resize(cap);
  ntris.assign(cap, 0);
  mov.assign(cap, 0);
}

void WholeSurfaceBvh::build(const format::Triangle* tris, std::uint32_t tri_count,
                            const double* positions, std::uint32_t leaf_size) noexcept {
  // By the median-split builder the asset's per-cluster BVHs come from.
  for (std::uint32_t t = 0; t < tri_count; ++t) {
    leaf[t] = t;
    for (int k = 0; k < 3; ++k) {
      double s = 0;
      for (std::uint32_t v : tris[t]) s += positions[std::size_t(v) * 3 + k];
      centroid[std::size_t(t) * 3 + k] = s / 3.0;
    }
  }
  count = build_median_bvh(centroid.data(), leaf.data(), tri_count, leaf_size, nodes.data(),
                           build_stack.data(), build_stack.size());
  for (std::uint32_t i = count; i-- > 0;) {
    const format::BvhNode& n = nodes[i];
    ntris[i] = n.count > 0 ? n.count : ntris[n.first] + ntris[n.second];
  }
  built = true;
}

namespace {

// Static orientation sign of det[a-o, b-o, c-o] with an error bound: +1, -1 or 0 (unknown).
int orient(const double* o, const double* a, const double* b, const double* c) noexcept {
  const BernsteinCubic k = orientation_bernstein(o, a, b, c, o, a, b, c);
  if (k.k[0] > k.err[0]) return 1;
  if (k.k[0] < -k.err[0]) return -1;
  return 0;
}

// Can segment pq meet triangle abc? False only when proven disjoint (floating point, with
// error bounds); near-degenerate and coplanar configurations count as meeting unless a 2D
// separation is clear. The 2D test runs whenever the 3D tests prove nothing: a flat face of a
// rotated body is coplanar only up to rounding, so its points may even lie certainly on both
// sides of a neighbour's plane. A projection of meeting sets meets, so a clear separation in
// the projection proves them disjoint in any configuration.
bool segment_meets_triangle(const double* p, const double* q, const double* a, const double* b,
                            const double* c) noexcept {
  const int sp = orient(a, b, c, p), sq = orient(a, b, c, q);
  if (sp != 0 && sp == sq) return false;
  const int s0 = orient(p, q, a, b), s1 = orient(p, q, b, c), s2 = orient(p, q, c, a);
  if ((s0 > 0 && (s1 < 0 || s2 < 0)) || (s0 < 0 && (s1 > 0 || s2 > 0)) || (s1 * s2 < 0))
    return false;
  {
    // Separate in the projection along the triangle's dominant normal axis.
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    int ax = 0;
    for (int k = 1; k < 3; ++k)
      if (std::fabs(n[k]) > std::fabs(n[ax])) ax = k;
    const int i = (ax + 1) % 3, j = (ax + 2) % 3;
    const double* tri[3] = {a, b, c};
    // Separating axis test in 2D over the triangle's edge normals and the segment's normal.
    auto separated = [&](double dx, double dy) {
      double tmin = INFINITY, tmax = -INFINITY, smin = INFINITY, smax = -INFINITY;
      for (const double* v : tri) {
        const double d = v[i] * dx + v[j] * dy;
        tmin = std::min(tmin, d);
        tmax = std::max(tmax, d);
      }
      for (const double* v : {p, q}) {
        const double d = v[i] * dx + v[j] * dy;
        smin = std::min(smin, d);
        smax = std::max(smax, d);
      }
      const double scale =
          1e-12 * (std::fabs(tmin) + std::fabs(tmax) + std::fabs(smin) + std::fabs(smax));
      return smax < tmin - scale || tmax < smin - scale;
    };
    for (int k = 0; k < 3; ++k) {
      const double* u = tri[k];
      const double* w = tri[(k + 1) % 3];
      if (separated(-(w[j] - u[j]), w[i] - u[i])) return false;
    }
    if (separated(-(q[j] - p[j]), q[i] - p[i])) return false;
  }
  return true;
}

}  // namespace

void rest_triangle_pair(Worker& w, const Collider::Impl& A, std::uint32_t t1,
                        const Collider::Impl& B, std::uint32_t t2) noexcept {
  const bool same = &A == &B;
  const auto& TA = A.tris[t1];
  const auto& TB = B.tris[t2];
  if (same) {
    int shared = 0;
    for (std::uint32_t u : TA)
      for (std::uint32_t v : TB) shared += u == v;
    if (shared >= 2) return;  // edge neighbours: only a flat fold could touch; not checked
  }
  for (int dir = 0; dir < 2 && !w.stop; ++dir) {
    const Collider::Impl& EB = dir == 0 ? A : B;  // body of the edges
    const Collider::Impl& FB = dir == 0 ? B : A;  // body of the triangle
    const auto& E = dir == 0 ? TA : TB;
    const auto& F = dir == 0 ? TB : TA;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t p = E[k], q = E[(k + 1) % 3];
      if (same && (p == F[0] || p == F[1] || p == F[2] || q == F[0] || q == F[1] || q == F[2]))
        continue;
      if (segment_meets_triangle(EB.pos0(p), EB.pos0(q), FB.pos0(F[0]), FB.pos0(F[1]),
                                 FB.pos0(F[2]))) {
        w.rest_hit = true;
        w.rest_a = same ? std::min(t1, t2) : t1;
        w.rest_b = same ? std::max(t1, t2) : t2;
        w.stop = true;
        return;
      }
    }
  }
}

RestCheck Collider::Impl::rest_check(const double* x, std::size_t value_count) noexcept {
  RestCheck r;
  r.status = begin_step(x, x, value_count, true);  // invalidates the current step
  if (r.status != ColliderStatus::kOk) return r;
  rest_mode = true;
  refit_and_classify();
  qkind = QueryKind::kAny;
  const bool ok = run_query(nullptr);  // rest mode: serial, worker 0
  rest_mode = false;
  have_step = false;
  stats = ColliderStats{};
  if (!ok) {
    r.status = ColliderStatus::kOverflow;
    return r;
  }
  r.intersecting = workers[0].rest_hit;
  r.triangle_a = workers[0].rest_a;
  r.triangle_b = workers[0].rest_b;
  r.bodies = {body_id, body_id};
  return r;
}

RestCheck Collider::check_rest_intersection(const double* x, std::size_t value_count) noexcept {
  if (!m_impl) {
    RestCheck r;
    r.status = ColliderStatus::kNotReady;
    return r;
  }
  return m_impl->rest_check(x, value_count);
}

}  // namespace tetseg
