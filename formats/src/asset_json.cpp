#include "tetseg/format/asset_json.hpp"

#include <cstdio>
#include <sstream>

namespace tetseg::format {

std::string json_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (unsigned char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out;
}

const char* body_kind_name(BodyKind kind) noexcept {
  switch (kind) {
    case BodyKind::kTet:
      return "tet";
    case BodyKind::kSurface:
      return "surface";
  }
  return "unknown";
}

const char* detector_form_name(DetectorForm form) noexcept {
  switch (form) {
    case DetectorForm::kTetPoint:
      return "tet-point";
    case DetectorForm::kSurfaceWeights:
      return "surface-weights";
    case DetectorForm::kBones:
      return "bones";
  }
  return "unknown";
}

std::string detector_json(const Asset& asset, const Cluster& cluster) {
  const DetectorPoint& d = cluster.detector;
  std::ostringstream out;
  out.precision(17);
  if (asset.detector_form != DetectorForm::kTetPoint) {
    out << "\"detector\": {\"form\": \"" << detector_form_name(asset.detector_form)
        << "\", \"terms\": [";
    for (std::uint32_t i = 0; i < cluster.detector_term_count; ++i) {
      const DetectorTerm& term = asset.detector_terms[cluster.detector_term_offset + i];
      out << (i ? ", " : "") << "[" << term.index << ", " << term.weight << "]";
    }
    const auto& p = cluster.detector_rest;
    out << "], \"position\": [" << p[0] << ", " << p[1] << ", " << p[2] << "]}";
    out << ", \"overlap_only\": " << ((cluster.flags & kClusterOverlapOnly) ? "true" : "false");
    return out.str();
  }
  out << "\"detector\": {\"nodes\": [" << d.nodes[0] << ", " << d.nodes[1] << ", " << d.nodes[2]
      << ", " << d.nodes[3] << "], \"weights\": [" << d.weights[0] << ", " << d.weights[1] << ", "
      << d.weights[2] << ", " << d.weights[3] << "], \"tet\": ";
  if (d.tet == kNoTet)
    out << "null";
  else
    out << d.tet;
  if (!asset.rest_positions.empty() && asset.rest_positions.size() == asset.node_count) {
    const auto p = detector_position(d, asset.rest_positions.front().data());
    out << ", \"position\": [" << p[0] << ", " << p[1] << ", " << p[2] << "]";
  }
  out << "}, \"overlap_only\": " << ((cluster.flags & kClusterOverlapOnly) ? "true" : "false");
  return out.str();
}

std::string provenance_options_json(const Asset& asset) {
  std::string out = "{";
  for (std::size_t i = 0; i < asset.provenance.options.size(); ++i) {
    const auto& [key, value] = asset.provenance.options[i];
    out += (i ? ", \"" : "\"") + json_escape(key) + "\": \"" + json_escape(value) + '"';
  }
  return out + "}";
}

}  // namespace tetseg::format
