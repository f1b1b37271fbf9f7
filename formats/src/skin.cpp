#include "tetseg/format/skin.hpp"

#include <cstddef>

namespace tetseg::format {

void skinned_detector_positions(const Asset& asset, const double* bone_matrices,
                                double* out) noexcept {
  const bool bones = asset.detector_form == DetectorForm::kBones;
  for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
    const Cluster& cl = asset.clusters[c];
    const std::array<double, 3>& r = cl.detector_rest;
    double* o = out + 3 * c;
    if (!bones || cl.detector_term_count == 0) {
      for (int k = 0; k < 3; ++k) o[k] = r[k];
      continue;
    }
    double sum[3] = {0.0, 0.0, 0.0};
    const DetectorTerm* terms = asset.detector_terms.data() + cl.detector_term_offset;
    for (std::uint32_t i = 0; i < cl.detector_term_count; ++i) {
      const double* m = bone_matrices + 12 * std::size_t(terms[i].index);
      for (int k = 0; k < 3; ++k) {
        const double* row = m + 4 * k;
        sum[k] += terms[i].weight * (row[0] * r[0] + row[1] * r[1] + row[2] * r[2] + row[3]);
      }
    }
    for (int k = 0; k < 3; ++k) o[k] = sum[k];
  }
}

}  // namespace tetseg::format
