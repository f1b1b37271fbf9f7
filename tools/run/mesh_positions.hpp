#pragma once
// Vertex positions from simple mesh files, for tetseg-frames: Wavefront .obj ("v" lines),
// .ply (ascii, binary little/big endian; the vertex element's x, y, z) and Medit .mesh
// (ascii "Vertices" section). Connectivity is ignored: the caller checks counts.

#include <string>
#include <vector>

namespace tetseg::tools {

/// xyz per vertex in file order. Throws ToolError(kExitBadInput) on unreadable or malformed
/// files and on non-finite coordinates.
std::vector<double> read_mesh_positions(const std::string& path);

}  // namespace tetseg::tools
