#pragma once
// Synthetic collider scenes without the preprocessor: closed surfaces over tet-node ids (surfaces
// of revolution: sphere, dumbbell, pawn, mushroom), clusters cut along z with detector nodes on the
// axis, per-cluster median-split BVHs, assets validated through tetseg::format, and deforming frame
// sequences. Header-only, runtime only; used by tetseg-scene and the collider tests.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/format/asset_io.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/median_bvh.hpp"

namespace tetseg::test {

using P3 = std::array<double, 3>;

struct Surface {
  std::vector<P3> verts;
  std::vector<format::Triangle> tris;
};

/// Makes the signed volume positive (outward winding).
inline void orient_outward(Surface& s) {
  double vol = 0;
  for (const auto& t : s.tris) {
    const P3 &a = s.verts[t[0]], &b = s.verts[t[1]], &c = s.verts[t[2]];
    vol += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  if (vol < 0)
    for (auto& t : s.tris) std::swap(t[1], t[2]);
}

/// Closed surface of revolution about the z axis. `profile` = (r, z) from the bottom pole
/// (r = 0) to the top pole (r = 0); `segments` vertices per ring; ring i is rotated by
/// i * `twist` radians (breaks symmetry). Triangles wound outward.
inline Surface revolve(const std::vector<std::array<double, 2>>& profile, int segments,
                       double twist = 0.0) {
  Surface s;
  const int m = static_cast<int>(profile.size());
  s.verts.push_back({0, 0, profile[0][1]});
  for (int i = 1; i < m - 1; ++i) {
    for (int j = 0; j < segments; ++j) {
      const double a = 2 * M_PI * j / segments + i * twist;
      s.verts.push_back({profile[i][0] * std::cos(a), profile[i][0] * std::sin(a), profile[i][1]});
    }
  }
  const std::uint32_t top = static_cast<std::uint32_t>(s.verts.size());
  s.verts.push_back({0, 0, profile[m - 1][1]});
  auto ring = [&](int i, int j) {
    return static_cast<std::uint32_t>(1 + (i - 1) * segments +
                                      ((j % segments) + segments) % segments);
  };
  for (int j = 0; j < segments; ++j) s.tris.push_back({0, ring(1, j + 1), ring(1, j)});
  for (int i = 1; i < m - 2; ++i) {
    for (int j = 0; j < segments; ++j) {
      s.tris.push_back({ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)});
      s.tris.push_back({ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)});
    }
  }
  for (int j = 0; j < segments; ++j) s.tris.push_back({top, ring(m - 2, j), ring(m - 2, j + 1)});
  orient_outward(s);
  return s;
}

inline std::vector<std::array<double, 2>> sample_profile(const std::function<double(double)>& r,
                                                         double z0, double z1, int rings) {
  std::vector<std::array<double, 2>> p;
  for (int i = 0; i <= rings + 1; ++i) {
    const double z = z0 + (z1 - z0) * i / (rings + 1);
    p.push_back({(i == 0 || i == rings + 1) ? 0.0 : r(z), z});
  }
  return p;
}

inline Surface sphere(double radius, int segments, int rings) {
  std::vector<std::array<double, 2>> p;
  for (int i = 0; i <= rings + 1; ++i) {
    const double th = M_PI * i / (rings + 1);
    p.push_back({i == 0 || i == rings + 1 ? 0.0 : radius * std::sin(th), -radius * std::cos(th)});
  }
  return revolve(p, segments, 0.37);
}

/// Two bells of radius 1 centred at z = -1.6 and z = 1.6 joined by a neck of radius 0.35.
inline Surface dumbbell(int segments, int rings) {
  auto r = [](double z) {
    const double a = std::fabs(z);
    const double bell = a > 0.6 ? std::sqrt(std::max(0.0, 1.0 - (a - 1.6) * (a - 1.6))) : 0.0;
    return std::max(0.35, bell);
  };
  return revolve(sample_profile(r, -2.6, 2.6, rings), segments, 0.21);
}

/// A chess pawn: base, body tapering to a collar, neck and a ball head. Height about 4.
inline Surface pawn(int segments, int rings) {
  auto r = [](double z) {
    if (z < 0.4) return 1.2;
    if (z < 0.6) return 1.2 - (z - 0.4) * 2.0;
    if (z < 2.4) return 0.8 - 0.4 * (z - 0.6) / 1.8;
    if (z < 2.6) return 0.75;
    if (z < 2.8) return 0.3;
    const double d = z - 3.3;
    return std::max(0.3, std::sqrt(std::max(0.0, 0.5 * 0.5 - d * d)) * 1.0 + 0.0);
  };
  return revolve(sample_profile(r, 0.0, 3.8, rings), segments, 0.13);
}

/// A mushroom: a cone stem widening downwards, a cap whose rim is a thin wedge (tip lower
/// than the underside at the stem). The rim's upper triangles face the detector, the lower
/// ones face away: the design note's wedge-tip configuration.
inline Surface mushroom(int segments) {
  std::vector<std::array<double, 2>> p = {
      {0.0, 0.0},  {2.6, 0.0},  {2.1, 0.5}, {1.6, 1.0},  {1.1, 1.5}, {0.6, 2.0},  // stem
      {0.9, 1.98}, {1.3, 1.9},  {1.7, 1.8}, {2.0, 1.72},                          // underside
      {2.2, 1.7},                                                                 // rim tip
      {2.0, 1.95}, {1.6, 2.15}, {1.1, 2.3}, {0.5, 2.4},  {0.0, 2.42}};            // top
  return revolve(p, segments, 0.0);
}

/// The runtime's median-split BVH (median_bvh.hpp) over `tris` (global ids) by centroid, in
/// the asset's layout: `order` receives the leaf order, `nodes` the nodes.
inline void build_bvh(const Surface& s, const std::vector<std::uint32_t>& tris,
                      std::uint32_t leaf_size, std::vector<std::uint32_t>& order,
                      std::vector<format::BvhNode>& nodes) {
  std::vector<double> centroids(s.tris.size() * 3);
  for (std::uint32_t t : tris)
    for (int k = 0; k < 3; ++k)
      centroids[std::size_t(t) * 3 + k] =
          (s.verts[s.tris[t][0]][k] + s.verts[s.tris[t][1]][k] + s.verts[s.tris[t][2]][k]) / 3;
  order = tris;
  nodes.assign(tris.empty() ? 0 : 2 * tris.size() - 1, {});
  MedianBvhTask stack[kMedianBvhStack];
  const std::uint32_t count =
      build_median_bvh(centroids.data(), order.data(), static_cast<std::uint32_t>(order.size()),
                       std::max<std::uint32_t>(leaf_size, 1), nodes.data(), stack, kMedianBvhStack);
  nodes.resize(count);
}

/// A valid but degenerate BVH: a chain whose depth equals the triangle count (each inner node
/// has one single-triangle leaf and the rest of the chain). Stresses traversal stacks.
inline void build_chain_bvh(const std::vector<std::uint32_t>& tris,
                            std::vector<std::uint32_t>& order,
                            std::vector<format::BvhNode>& nodes) {
  order = tris;
  nodes.clear();
  const std::uint32_t n = static_cast<std::uint32_t>(tris.size());
  for (std::uint32_t k = 0; k + 1 < n; ++k) {
    const std::uint32_t self = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back({self + 1, self + 2, 0});
    nodes.push_back({k, 0, 1});
  }
  nodes.push_back({n - 1, 0, 1});
}

/// A scene: the asset plus rest positions of all nodes (surface vertices, then detectors).
struct Scene {
  Asset asset;
  std::vector<double> rest;  // node_count * 3
  std::uint32_t surface_nodes = 0;
};

/// Validates, writes and loads `a` as a scene whose first `surface_nodes` nodes are the
/// surface's vertices. Throws std::runtime_error when the asset is invalid.
inline Scene load_scene(const format::Asset& a, std::uint32_t surface_nodes) {
  std::string why;
  if (format::validate(a, &why) != format::Status::kOk)
    throw std::runtime_error("invalid test asset: " + why);
  const std::vector<std::uint8_t> bytes = format::write_asset(a);
  Scene scene;
  if (load_asset(bytes.data(), bytes.size(), scene.asset, &why) != format::Status::kOk)
    throw std::runtime_error("test asset does not load: " + why);
  for (const P3& p : a.rest_positions) scene.rest.insert(scene.rest.end(), p.begin(), p.end());
  scene.surface_nodes = surface_nodes;
  return scene;
}

/// Assembles, validates and loads an asset. `cluster_of[t]` in [0, detectors.size()).
/// `leaf_size` 0 builds chain BVHs (build_chain_bvh) instead of median splits.
inline Scene make_scene(const Surface& s, const std::vector<std::uint32_t>& cluster_of,
                        const std::vector<P3>& detectors, std::uint32_t leaf_size = 2) {
  format::Asset a;
  const std::uint32_t nv = static_cast<std::uint32_t>(s.verts.size());
  a.node_count = nv + static_cast<std::uint32_t>(detectors.size());
  a.rest_positions = s.verts;
  a.rest_positions.insert(a.rest_positions.end(), detectors.begin(), detectors.end());
  a.triangles = s.tris;
  a.triangle_cluster = cluster_of;
  for (std::uint32_t c = 0; c < detectors.size(); ++c) {
    std::vector<std::uint32_t> tris;
    for (std::uint32_t t = 0; t < s.tris.size(); ++t)
      if (cluster_of[t] == c) tris.push_back(t);
    if (tris.empty()) throw std::runtime_error("empty cluster in test scene");
    std::vector<std::uint32_t> order;
    std::vector<format::BvhNode> nodes;
    if (leaf_size == 0) {
      build_chain_bvh(tris, order, nodes);
    } else {
      build_bvh(s, tris, leaf_size, order, nodes);
    }
    format::Cluster cl;
    cl.detector = format::DetectorPoint::at_node(nv + c);
    cl.rest_positive_fraction = 1.0f;
    cl.triangle_offset = static_cast<std::uint32_t>(a.cluster_triangles.size());
    cl.triangle_count = static_cast<std::uint32_t>(order.size());
    cl.bvh_offset = static_cast<std::uint32_t>(a.bvh_nodes.size());
    cl.bvh_count = static_cast<std::uint32_t>(nodes.size());
    a.cluster_triangles.insert(a.cluster_triangles.end(), order.begin(), order.end());
    a.bvh_nodes.insert(a.bvh_nodes.end(), nodes.begin(), nodes.end());
    a.clusters.push_back(cl);
  }
  a.provenance.tool_version = "tetseg tests";
  return load_scene(a, nv);
}

/// The scene's asset with every cluster's detector moved into a small tet of its own: four new
/// nodes (appended after all others, 4 per cluster, in cluster order) around the old detector
/// position at distance `radius`, the detector the point with `weights` in it (point form,
/// tet id = cluster id). The old detector nodes stay (unread). Positions of the new nodes
/// follow the deformation like every node; tests may move them on their own.
inline Scene with_detector_tets(const Scene& scene, double radius,
                                const std::array<double, 4>& weights = {0.4, 0.3, 0.2, 0.1}) {
  format::Asset a = scene.asset.data();
  const P3 corner[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  for (std::uint32_t c = 0; c < a.clusters.size(); ++c) {
    const P3 center = a.rest_positions[a.clusters[c].detector.nodes[0]];
    format::DetectorPoint d;
    for (int i = 0; i < 4; ++i) {
      d.nodes[i] = a.node_count++;
      a.rest_positions.push_back({center[0] + radius * corner[i][0],
                                  center[1] + radius * corner[i][1],
                                  center[2] + radius * corner[i][2]});
    }
    d.weights = weights;
    d.tet = c;
    a.clusters[c].detector = d;
  }
  return load_scene(a, scene.surface_nodes);
}

/// The scene's asset with `flags` (e.g. format::kClusterOverlapOnly) set on every cluster.
inline Scene with_cluster_flags(const Scene& scene, std::uint32_t flags) {
  format::Asset a = scene.asset.data();
  for (format::Cluster& c : a.clusters) c.flags = flags;
  return load_scene(a, scene.surface_nodes);
}

/// Clusters by triangle-centroid z: cut at `cuts` (ascending); detectors on the axis at
/// `detector_z` (one more than cuts); BVH leaves as make_scene's `leaf_size`.
inline Scene make_axial_scene(const Surface& s, const std::vector<double>& cuts,
                              const std::vector<double>& detector_z, std::uint32_t leaf_size = 2) {
  std::vector<std::uint32_t> cluster_of(s.tris.size());
  for (std::size_t t = 0; t < s.tris.size(); ++t) {
    const double z =
        (s.verts[s.tris[t][0]][2] + s.verts[s.tris[t][1]][2] + s.verts[s.tris[t][2]][2]) / 3;
    cluster_of[t] =
        static_cast<std::uint32_t>(std::upper_bound(cuts.begin(), cuts.end(), z) - cuts.begin());
  }
  std::vector<P3> det;
  for (double z : detector_z) det.push_back({0.0, 0.0, z});
  return make_scene(s, cluster_of, det, leaf_size);
}

/// Frames of a deformation: frame f = map(rest position, f / (frames - 1)) for every node.
using Deformation = std::function<P3(const P3&, double)>;
inline std::vector<std::vector<double>> make_frames(const Scene& scene, int frames,
                                                    const Deformation& map) {
  std::vector<std::vector<double>> out(frames);
  for (int f = 0; f < frames; ++f) {
    const double t = frames > 1 ? double(f) / (frames - 1) : 0.0;
    out[f].resize(scene.rest.size());
    for (std::size_t n = 0; n < scene.rest.size() / 3; ++n) {
      const P3 p = map({scene.rest[3 * n], scene.rest[3 * n + 1], scene.rest[3 * n + 2]}, t);
      for (int k = 0; k < 3; ++k) out[f][3 * n + k] = p[k];
    }
  }
  return out;
}

/// 0 below a, 1 above b, cubic Hermite blend between.
inline double smoothstep(double x, double a, double b) {
  const double s = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return s * s * (3 - 2 * s);
}

/// Rotates everything above z0..z1 about the x axis through pivot_z, up to `max_angle` radians
/// at t = 1, blended over z0..z1.
inline P3 bend_about_x(const P3& p, double t, double max_angle, double z0, double z1,
                       double pivot_z) {
  const double a = t * max_angle * smoothstep(p[2], z0, z1);
  const double y = p[1], z = p[2] - pivot_z;
  return {p[0], y * std::cos(a) - z * std::sin(a), pivot_z + y * std::sin(a) + z * std::cos(a)};
}

/// Pushes both poles of a sphere towards the centre until the dents meet (t ~ 0.77). The dents
/// are off-centre so that the first contact is generic (press_poles_head_on is the degenerate
/// variant).
inline P3 press_poles(const P3& p, double t) {
  const double cx = p[2] > 0 ? 0.15 : -0.1, cy = p[2] > 0 ? 0.1 : -0.05;
  const double w = std::exp(-((p[0] - cx) * (p[0] - cx) + (p[1] - cy) * (p[1] - cy)) / 0.3);
  const double dz = (p[2] > 0 ? -1.0 : 1.0) * 1.3 * t * w * std::min(1.0, std::fabs(p[2]) * 4);
  return {p[0] + 0.15 * dz, p[1] + 0.05 * dz, p[2] + dz};
}

/// Twists a pawn of height ~4 about z (2.5 rad at the top) and bends its upper part over.
inline P3 twist_bend(const P3& p, double t) {
  const double tw = t * 2.5 * smoothstep(p[2], 0.5, 3.5);
  const P3 q = {p[0] * std::cos(tw) - p[1] * std::sin(tw),
                p[0] * std::sin(tw) + p[1] * std::cos(tw), p[2]};
  return bend_about_x(q, t, 3.0, 0.8, 2.6, 1.0);
}

/// Pushes both poles of a unit sphere about the z axis straight towards the centre (a Gaussian
/// dent of width 0.3 each): the poles meet head on at one point (t ~ 0.77 on sphere(1, 20, 11)),
/// the degenerate meeting where many feature pairs touch at once (docs/runtime.md).
inline P3 press_poles_head_on(const P3& p, double t) {
  const double w = std::exp(-(p[0] * p[0] + p[1] * p[1]) / 0.3);
  const double dz = (p[2] > 0 ? -1.0 : 1.0) * 1.3 * t * w * std::min(1.0, std::fabs(p[2]) * 4);
  return P3{p[0], p[1], p[2] + dz};
}

/// Applies x -> scale * x + offset to every frame.
inline std::vector<std::vector<double>> transformed(std::vector<std::vector<double>> frames,
                                                    double scale, const P3& offset) {
  for (auto& f : frames)
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = scale * f[i] + offset[i % 3];
  return frames;
}

}  // namespace tetseg::test
