// Minimal use of the runtime collider (docs/runtime.md): load an asset, step through a frame
// sequence, read the earliest contact and all contacts into a caller-owned buffer.
//   tetseg-collider-example <asset.tetseg> <frames.tsf>

#include <cstdio>
#include <vector>

#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/frames.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <asset> <frames>\n", argv[0]);
    return 2;
  }
  tetseg::Asset asset;
  if (tetseg::load_asset_file(argv[1], asset) != tetseg::Status::kOk) return 3;
  tetseg::FrameSequence frames;
  if (tetseg::read_frames_file(argv[2], frames) != tetseg::FramesStatus::kOk) return 3;
  if (frames.node_count != asset.node_count()) return 3;

  tetseg::Collider collider(asset);             // allocates all scratch once
  std::vector<tetseg::Contact> contacts(1024);  // caller-owned output buffer
  for (std::uint32_t f = 0; f + 1 < frames.frame_count; ++f) {
    // Positions must stay valid until the queries of this step are done.
    if (collider.step(frames.frame(f), frames.frame(f + 1)) != tetseg::ColliderStatus::kOk)
      return 3;
    // Every query returns a status; only kOk comes with an answer.
    bool hit = false;
    if (collider.any_collision(hit) != tetseg::ColliderStatus::kOk) return 3;
    if (!hit) continue;  // cheap: stops at the first contact
    tetseg::EarliestContact first;
    tetseg::ContactsResult all;
    if (collider.earliest_toi(first) != tetseg::ColliderStatus::kOk ||
        collider.contacts(contacts.data(), contacts.size(), all) != tetseg::ColliderStatus::kOk)
      return 3;
    std::printf(
        "step %u: first contact at t = %.6f (%s), %zu contacts%s\n", f, first.contact.toi,
        first.contact.kind == tetseg::ContactKind::kVertexFace ? "vertex-face" : "edge-edge",
        all.found, all.truncated() ? " (truncated)" : "");
    return 0;  // a simulator would now respond to the contact
  }
  std::printf("no contact\n");
  return 0;
}
