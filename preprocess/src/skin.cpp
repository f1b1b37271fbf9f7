// Skin weights mapped onto a surface's vertices, and bone-carried detector terms (skin.hpp).
// Reading skins is in io_assimp.cpp (the only unit that includes assimp).

#include "tetseg/preprocess/skin.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace tetseg::preprocess {

namespace {

bool same_influences(const std::vector<BoneInfluence>& a, const std::vector<BoneInfluence>& b) {
  constexpr double kTolerance = 1e-6;
  std::size_t i = 0, j = 0;
  // Both sorted by bone; a bone missing on one side counts as weight 0.
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && a[i].bone < b[j].bone)) {
      if (a[i++].weight > kTolerance) return false;
    } else if (i == a.size() || b[j].bone < a[i].bone) {
      if (b[j++].weight > kTolerance) return false;
    } else {
      if (std::fabs(a[i++].weight - b[j++].weight) > kTolerance) return false;
    }
  }
  return true;
}

std::string position_text(const Vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.9g, %.9g, %.9g)", p[0], p[1], p[2]);
  return text;
}

}  // namespace

std::vector<std::vector<BoneInfluence>> skin_weights_at(const Skin& skin,
                                                        const std::vector<Vec3>& vertices,
                                                        const std::string& path) {
  std::map<Vec3, std::uint32_t> skin_vertex_at;
  for (std::uint32_t v = 0; v < skin.vertices.size(); ++v) {
    const auto [it, inserted] = skin_vertex_at.emplace(skin.vertices[v], v);
    if (!inserted && !same_influences(skin.influences[it->second], skin.influences[v]))
      throw InputError(path, "skin vertices " + std::to_string(it->second) + " and " +
                                 std::to_string(v) + " share the position " +
                                 position_text(skin.vertices[v]) + " but not their bone weights");
  }
  std::vector<std::vector<BoneInfluence>> out;
  out.reserve(vertices.size());
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    const auto it = skin_vertex_at.find(vertices[v]);
    if (it == skin_vertex_at.end())
      throw InputError(
          path, "surface vertex " + std::to_string(v) + " at " + position_text(vertices[v]) +
                    " has no skinned vertex at its position (" + std::to_string(vertices.size()) +
                    " surface vertices, " + std::to_string(skin.vertices.size()) + " skinned)");
    out.push_back(skin.influences[it->second]);
  }
  return out;
}

std::vector<format::DetectorTerm> bone_detector_terms(
    const std::vector<std::vector<BoneInfluence>>& vertex_influences,
    const std::vector<Tri>& triangles, const std::vector<std::uint32_t>& cluster_triangles,
    std::uint32_t max_terms) {
  std::vector<std::uint32_t> corners;
  for (std::uint32_t t : cluster_triangles)
    for (std::uint32_t v : triangles.at(t)) corners.push_back(v);
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  std::map<std::uint32_t, double> sum_by_bone;
  for (std::uint32_t v : corners)
    for (const BoneInfluence& influence : vertex_influences.at(v))
      sum_by_bone[influence.bone] += influence.weight;
  std::vector<format::DetectorTerm> terms;
  for (const auto& [bone, weight] : sum_by_bone) terms.push_back({bone, weight});
  std::stable_sort(terms.begin(), terms.end(),
                   [](const auto& a, const auto& b) { return a.weight > b.weight; });
  if (terms.size() > max_terms) terms.resize(std::max<std::uint32_t>(max_terms, 1));
  double total = 0;
  for (const auto& term : terms) total += term.weight;
  for (auto& term : terms) term.weight /= total;
  std::sort(terms.begin(), terms.end(),
            [](const auto& a, const auto& b) { return a.index < b.index; });
  return terms;
}

void carry_detectors_by_bones(format::Asset& asset, const std::vector<Vec3>& vertices,
                              const Skin& skin, const std::string& path, std::uint32_t max_terms) {
  if (asset.body_kind != format::BodyKind::kSurface)
    throw std::invalid_argument("carry_detectors_by_bones: not a surface body");
  if (vertices.size() != asset.node_count)
    throw std::invalid_argument("carry_detectors_by_bones: not the asset's vertices");
  if (skin.bone_names.size() > format::kMaxBones)
    throw InputError(path, std::to_string(skin.bone_names.size()) + " bones, more than " +
                               std::to_string(format::kMaxBones));
  const auto influences = skin_weights_at(skin, vertices, path);
  std::vector<Tri> triangles(asset.triangles.begin(), asset.triangles.end());
  std::vector<format::DetectorTerm> terms;
  std::vector<format::Cluster> clusters = asset.clusters;
  for (format::Cluster& c : clusters) {
    c.detector_term_offset = static_cast<std::uint32_t>(terms.size());
    c.detector_term_count = 0;
    if (c.flags & format::kClusterOverlapOnly) continue;
    const std::vector<std::uint32_t> own(
        asset.cluster_triangles.begin() + c.triangle_offset,
        asset.cluster_triangles.begin() + c.triangle_offset + c.triangle_count);
    const auto cluster_terms = bone_detector_terms(influences, triangles, own, max_terms);
    terms.insert(terms.end(), cluster_terms.begin(), cluster_terms.end());
    c.detector_term_count = static_cast<std::uint32_t>(cluster_terms.size());
  }
  asset.clusters = std::move(clusters);
  asset.detector_terms = std::move(terms);
  asset.detector_form = format::DetectorForm::kBones;
  asset.bone_names = skin.bone_names;
}

}  // namespace tetseg::preprocess
