#pragma once
// tetseg-bench surface: a tet scene as a surface body (docs/benchmarks.md, "Surface bodies").

#include <string>
#include <vector>

namespace tetseg::bench {

/// Writes the rest surface of the tet asset `asset_path` as an OFF file (`surface_path`): its
/// surface nodes in ascending node id as vertices, its triangles in order, renumbered; and
/// each frame file of `frame_pairs` (FRAMES OUT_FRAMES, repeated) restricted to those nodes,
/// so that the surface asset built from the OFF (`tetseg build --body surface`) steps through
/// the same motion. Returns the exit code (0; 3 for bad input, with a message on stderr).
int surface_frames(const std::string& asset_path, const std::string& surface_path,
                   const std::vector<std::string>& frame_pairs);

}  // namespace tetseg::bench
