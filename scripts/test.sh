#!/usr/bin/env bash
# Quick start, part 2: installs dependencies, builds everything and runs every test:
#  1. the full build (preprocess, tools, tests) and ctest;
#  2. a runtime-only build with CGAL, Eigen and assimp made unfindable, and its tests;
#  3. install of the runtime package and a consumer project built with find_package(tetseg);
#  4. the loader fuzz target, briefly, when clang with libFuzzer is available;
#  5. every C++ source follows .clang-format (scripts/check-format.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
jobs=${TETSEG_JOBS:-$(nproc)}
bash scripts/install-deps.sh

echo "== full build and tests"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_REQUIRE_TEST_DATA=ON
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== runtime-only build (no CGAL, Eigen, assimp)"
cmake -S . -B build-runtime-only -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_BUILD_PREPROCESS=OFF \
  -DTETSEG_REQUIRE_TEST_DATA=ON \
  -DCMAKE_DISABLE_FIND_PACKAGE_CGAL=ON -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON \
  -DCMAKE_DISABLE_FIND_PACKAGE_assimp=ON
cmake --build build-runtime-only -j "$jobs"
ctest --test-dir build-runtime-only --output-on-failure -j "$jobs"

echo "== install and find_package(tetseg) consumer"
rm -rf build-install/prefix
cmake --install build-runtime-only --prefix "$root/build-install/prefix"
cmake -S tests/install-consumer -B build-install/consumer -G Ninja \
  -DCMAKE_PREFIX_PATH="$root/build-install/prefix"
cmake --build build-install/consumer
build-install/consumer/tetseg_consumer tests/golden/*.tetseg

if command -v clang++ >/dev/null && [ -e /usr/lib/llvm-14/lib/clang/14.0.6/lib/linux/libclang_rt.fuzzer-x86_64.a ]; then
  echo "== loader fuzz target (60 s)"
  CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DTETSEG_BUILD_PREPROCESS=OFF -DTETSEG_BUILD_TOOLS=OFF -DTETSEG_BUILD_FUZZERS=ON
  cmake --build build-fuzz -j "$jobs" --target fuzz_load_asset
  mkdir -p build-fuzz/corpus
  cp tests/golden/*.tetseg build-fuzz/corpus/
  build-fuzz/tests/fuzz/fuzz_load_asset -max_total_time=60 build-fuzz/corpus
fi
echo "== format"
bash scripts/check-format.sh
echo "== all tests passed"
