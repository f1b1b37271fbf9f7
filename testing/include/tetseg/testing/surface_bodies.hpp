#pragma once
// Surface bodies (asset format 1.2) without the preprocessor: a synthetic tet scene
// (synthetic_scenes.hpp: surface vertices first, detector nodes after them) turned into a
// kSurface asset over its surface vertices alone, with the same triangles, clusters and BVHs,
// and detectors given either by weights of a few surface vertices (kSurfaceWeights) or carried
// by bones (kBones). Header-only; used by the runtime tests and benchmark drivers.

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

namespace tetseg::test {

/// The distinct vertices of cluster c's triangles, ascending.
inline std::vector<std::uint32_t> cluster_vertices(const format::Asset& a, std::size_t c) {
  const format::Cluster& cl = a.clusters[c];
  std::vector<std::uint32_t> v;
  for (std::uint32_t i = 0; i < cl.triangle_count; ++i) {
    const format::Triangle& t = a.triangles[a.cluster_triangles[cl.triangle_offset + i]];
    v.insert(v.end(), t.begin(), t.end());
  }
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

/// `scene`'s asset as a surface body: nodes = its first `surface_nodes` nodes (the surface
/// vertices, in order), every 1.1 detector replaced by the unused node form, form `form` with no
/// terms yet (the callers add them).
inline format::Asset surface_asset_base(const Scene& scene, format::DetectorForm form) {
  format::Asset a = scene.asset.data();
  a.node_count = scene.surface_nodes;
  a.rest_positions.resize(scene.surface_nodes);
  a.body_kind = format::BodyKind::kSurface;
  a.detector_form = form;
  for (format::Cluster& c : a.clusters) {
    c.detector = format::DetectorPoint::at_node(0);
    c.detector_term_offset = 0;
    c.detector_term_count = 0;
  }
  return a;
}

/// A kSurfaceWeights surface body from `scene`: cluster c's detector is the mean of `terms`
/// vertices spread evenly over the vertex list of cluster (c + shift) % clusters (shift 0: its
/// own vertices, so the point lies inside the hull of its own part; another shift puts it in
/// another part, far from its own). Overlap-only clusters keep their flag and terms.
inline Scene as_weighted_surface_body(const Scene& scene, std::uint32_t terms = 4,
                                      std::uint32_t shift = 0) {
  format::Asset a = surface_asset_base(scene, format::DetectorForm::kSurfaceWeights);
  const std::size_t n = a.clusters.size();
  for (std::size_t c = 0; c < n; ++c) {
    const std::vector<std::uint32_t> verts = cluster_vertices(a, (c + shift) % n);
    const std::uint32_t k = std::min<std::uint32_t>(terms, std::uint32_t(verts.size()));
    format::Cluster& cl = a.clusters[c];
    cl.detector_term_offset = static_cast<std::uint32_t>(a.detector_terms.size());
    cl.detector_term_count = k;
    for (std::uint32_t i = 0; i < k; ++i)
      a.detector_terms.push_back({verts[std::size_t(i) * verts.size() / k], 1.0 / k});
    cl.detector_rest = format::weighted_detector_position(
        a.detector_terms.data() + cl.detector_term_offset, k, a.rest_positions.front().data());
  }
  return load_scene(a, scene.surface_nodes);
}

/// A kBones surface body from `scene` with `bones` bones ("bone0", ...): cluster c's detector
/// rests where the scene's tet detector rests and is carried by bone c % bones (weight 0.75)
/// and bone (c + 1) % bones (0.25), or by one bone when there is only one.
inline Scene as_bone_surface_body(const Scene& scene, std::uint32_t bones) {
  const format::Asset& tet = scene.asset.data();
  format::Asset a = surface_asset_base(scene, format::DetectorForm::kBones);
  for (std::uint32_t b = 0; b < bones; ++b) a.bone_names.push_back("bone" + std::to_string(b));
  for (std::size_t c = 0; c < a.clusters.size(); ++c) {
    format::Cluster& cl = a.clusters[c];
    cl.detector_term_offset = static_cast<std::uint32_t>(a.detector_terms.size());
    const auto first = static_cast<std::uint32_t>(c % bones);
    if (bones == 1) {
      a.detector_terms.push_back({first, 1.0});
    } else {
      a.detector_terms.push_back({first, 0.75});
      a.detector_terms.push_back({(first + 1) % bones, 0.25});
    }
    cl.detector_term_count = bones == 1 ? 1 : 2;
    cl.detector_rest =
        format::detector_position(tet.clusters[c].detector, tet.rest_positions.front().data());
  }
  return load_scene(a, scene.surface_nodes);
}

}  // namespace tetseg::test
