// libFuzzer harness for the asset reader. It must never crash, and it must be deterministic:
// the same bytes give the same status twice, and an accepted input re-writes to exactly the
// bytes it was read from (the encoding is canonical) and to the same bytes every time. The
// one exception (docs/format.md, "Determinism"): an input that needs only an older minor (a
// 1.1 input that needs nothing of 1.1, a 1.2 one with a kTet body and kTetPoint detectors) is
// re-written in that minor, which must read back to an asset that writes the same bytes again.
//
// Each input is read twice over: as given (exercises the envelope checks), and "resealed"
// with payload size and both checksums recomputed, so mutations of the payload reach the
// decoder and the validator instead of stopping at the payload checksum.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "crc32c.hpp"  // formats/src: the harness is compiled with the format sources
#include "tetseg/format/asset_io.hpp"

namespace {

using tetseg::format::Asset;
using tetseg::format::Status;

[[noreturn]] void fail(const char* what, Status s) {
  std::fprintf(stderr, "fuzz_load_asset: %s (status %s)\n", what, tetseg::format::to_string(s));
  std::abort();
}

void put_le(std::uint8_t* p, std::uint64_t v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

void check(const std::uint8_t* data, std::size_t size) {
  Asset first;
  Asset second;
  std::string why_first;
  std::string why_second;
  const Status s1 = tetseg::format::read_asset(data, size, first, &why_first);
  const Status s2 = tetseg::format::read_asset(data, size, second, &why_second);
  if (s1 != s2) fail("two reads of the same bytes disagree", s1);
  if (why_first != why_second) fail("two reads of the same bytes explain differently", s1);
  if (s1 != Status::kOk) {
    if (!first.triangles.empty() || !first.clusters.empty() || !first.bvh_nodes.empty() ||
        first.node_count != 0) {
      fail("a failed read left data in the asset", s1);
    }
    if (why_first.empty()) fail("a failed read gave no detail", s1);
    return;
  }
  if (tetseg::format::validate(first) != Status::kOk)
    fail("an accepted asset does not validate", s1);
  const std::vector<std::uint8_t> bytes = tetseg::format::write_asset(first);
  if (bytes != tetseg::format::write_asset(second)) fail("re-writing is not deterministic", s1);
  std::uint16_t major = 0, minor = 0;
  tetseg::format::peek_version(data, size, major, minor);
  if (minor > tetseg::format::minor_version_needed(first)) {
    Asset again;
    if (tetseg::format::read_asset(bytes.data(), bytes.size(), again) != Status::kOk ||
        tetseg::format::write_asset(again) != bytes) {
      fail("an input written in an older minor does not read back", s1);
    }
    return;
  }
  if (bytes.size() != size || !std::equal(bytes.begin(), bytes.end(), data)) {
    fail("an accepted input does not re-write to the same bytes", s1);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  check(data, size);
  constexpr std::size_t kHeader = tetseg::format::kEnvelopeBytes;
  if (size >= kHeader) {
    // Exactly sized copy, so ASan still sees reads past the end.
    std::vector<std::uint8_t> resealed(data, data + size);
    std::uint8_t* h = resealed.data();
    put_le(h + 20, size - kHeader, 8);
    put_le(h + 28, tetseg::format::detail::crc32c(h + kHeader, size - kHeader), 4);
    put_le(h + 32, tetseg::format::detail::crc32c(h, 32), 4);
    check(resealed.data(), resealed.size());
  }
  return 0;
}
