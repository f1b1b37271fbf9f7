// tetseg-bench surface (surface_frames.hpp).

#include "surface_frames.hpp"

#include <cstdio>
#include <string>
#include <vector>

#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/frames.hpp"
#include "tool_support.hpp"

namespace tetseg::bench {

int surface_frames(const std::string& asset_path, const std::string& surface_path,
                   const std::vector<std::string>& frame_pairs) {
  std::string why;
  tetseg::Asset asset;
  if (tetseg::load_asset_file(asset_path, asset, &why) != tetseg::Status::kOk) {
    std::fprintf(stderr, "tetseg-bench: error: %s: %s\n", asset_path.c_str(), why.c_str());
    return 3;
  }
  const format::Asset& a = asset.data();
  if (a.rest_positions.size() != a.node_count) {
    std::fprintf(stderr, "tetseg-bench: error: %s: no rest positions\n", asset_path.c_str());
    return 3;
  }
  constexpr std::uint32_t kNone = 0xffffffffu;
  std::vector<std::uint32_t> vertex_of(a.node_count, kNone);
  for (const format::Triangle& t : a.triangles)
    for (std::uint32_t n : t) vertex_of[n] = 0;
  std::vector<std::uint32_t> nodes;  // surface nodes, ascending
  for (std::uint32_t n = 0; n < a.node_count; ++n)
    if (vertex_of[n] != kNone) {
      vertex_of[n] = static_cast<std::uint32_t>(nodes.size());
      nodes.push_back(n);
    }
  std::string off =
      "OFF\n" + std::to_string(nodes.size()) + " " + std::to_string(a.triangles.size()) + " 0\n";
  char line[128];
  for (std::uint32_t n : nodes) {
    const auto& p = a.rest_positions[n];
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", p[0], p[1], p[2]);
    off += line;
  }
  for (const format::Triangle& t : a.triangles) {
    std::snprintf(line, sizeof line, "3 %u %u %u\n", vertex_of[t[0]], vertex_of[t[1]],
                  vertex_of[t[2]]);
    off += line;
  }
  tools::write_file_atomic(surface_path, off);
  for (std::size_t i = 0; i + 1 < frame_pairs.size(); i += 2) {
    FrameSequence in;
    if (read_frames_file(frame_pairs[i], in, &why) != FramesStatus::kOk ||
        in.node_count != a.node_count) {
      std::fprintf(stderr, "tetseg-bench: error: %s: %s\n", frame_pairs[i].c_str(),
                   why.empty() ? "node count differs from the asset's" : why.c_str());
      return 3;
    }
    FrameSequence out;
    out.node_count = static_cast<std::uint32_t>(nodes.size());
    out.frame_count = in.frame_count;
    out.positions.reserve(std::size_t(out.frame_count) * nodes.size() * 3);
    for (std::uint32_t f = 0; f < in.frame_count; ++f)
      for (std::uint32_t n : nodes)
        for (int k = 0; k < 3; ++k) out.positions.push_back(in.frame(f)[3 * std::size_t(n) + k]);
    const std::vector<std::uint8_t> bytes = write_frames(out);
    tools::write_file_atomic(frame_pairs[i + 1], bytes.data(), bytes.size());
  }
  return 0;
}

}  // namespace tetseg::bench
