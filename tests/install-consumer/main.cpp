// Loads each asset given on the command line with the installed runtime; exit 0 when all load.
#include <cstdio>
#include <string>

#include "tetseg/runtime/asset.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: tetseg_consumer ASSET...\n");
    return 2;
  }
  for (int i = 1; i < argc; ++i) {
    tetseg::Asset asset;
    std::string detail;
    const tetseg::Status status = tetseg::load_asset_file(argv[i], asset, &detail);
    if (status != tetseg::Status::kOk) {
      std::fprintf(stderr, "tetseg_consumer: %s: %s (%s)\n", argv[i], tetseg::to_string(status),
                   detail.c_str());
      return 1;
    }
    std::printf("%s: %zu triangles, %zu clusters\n", argv[i], asset.triangle_count(),
                asset.cluster_count());
  }
  return 0;
}
