// tetseg-frames: builds a frame-sequence file (docs/format.md) from a list of meshes with
// fixed connectivity, one per frame, in order. Vertex i of every file is tet-mesh node i.

#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "mesh_io.hpp"
#include "tetseg/runtime/frames.hpp"
#include "tool_support.hpp"

int main(int argc, char** argv) {
  using namespace tetseg::tools;
  CLI::App app{"tetseg-frames " TETSEG_VERSION
               ": frame-sequence file from .obj/.ply/.mesh files with fixed connectivity",
               "tetseg-frames"};
  app.set_version_flag("--version", "tetseg-frames " TETSEG_VERSION);
  std::string out;
  std::vector<std::string> inputs;
  app.add_option("output", out, "Frame-sequence file to write")->required();
  app.add_option("inputs", inputs, "One mesh per frame, in order")->required();
  return run_tool("tetseg-frames", app, argc, argv, [&] {
    tetseg::FrameSequence frames;
    for (const std::string& path : inputs) {
      std::vector<double> xyz;
      const tetseg::io::IoStatus read = tetseg::io::read_vertex_positions(path, xyz);
      if (!read.ok()) throw ToolError(kExitBadInput, path, read.error);
      const std::uint32_t nodes = static_cast<std::uint32_t>(xyz.size() / 3);
      if (frames.frame_count == 0) frames.node_count = nodes;
      if (nodes != frames.node_count)
        throw ToolError(kExitBadInput, path,
                        "has " + std::to_string(nodes) + " vertices, the first frame has " +
                            std::to_string(frames.node_count));
      frames.positions.insert(frames.positions.end(), xyz.begin(), xyz.end());
      ++frames.frame_count;
    }
    write_file_atomic(out, tetseg::write_frames(frames));
    std::cerr << "tetseg-frames: " << frames.frame_count << " frames of " << frames.node_count
              << " nodes -> " << out << '\n';
    return kExitOk;
  });
}
