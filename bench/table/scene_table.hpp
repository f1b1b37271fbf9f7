#pragma once
/// \file
/// `tetseg-bench scene`: the scene table over scene descriptions written by `tetseg-sim
/// --scene` (docs/format.md, "Scene descriptions"): per-step time by stage through a
/// `tetseg::Scene`, bodies, body pairs tested and skipped, contacts, and the contacts missed
/// against the brute-force oracle over the whole scene (tetseg/testing/scene_oracle.hpp);
/// optionally the same steps through one `bvh` body over all surfaces merged.

#include <cstddef>
#include <string>
#include <vector>

namespace tetseg::bench {

struct SceneTableOptions {
  std::vector<std::string> scenes;  ///< NAME DESCRIPTION pairs
  std::size_t stride = 1;           ///< step from frame f to f + stride
  std::size_t max_steps = 1000000;  ///< steps per scene at most
  int repeat = 3;                   ///< runs per step, the fastest kept
  bool truth = true;                ///< run the oracle and compare
  bool merged = false;              ///< also time all surfaces merged into one bvh body
  bool expect_clean = false;        ///< fail when any frame intersects or any step has a contact
};

/// Prints the Markdown table on stdout. Returns 0; 1 when a contact was missed or invented
/// (or, with `expect_clean`, a frame or step is not clean). A bad input throws
/// tools::ToolError(kExitBadInput) naming the file in its message.
int scene_table(const SceneTableOptions& options);

}  // namespace tetseg::bench
