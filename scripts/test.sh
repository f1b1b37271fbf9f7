#!/usr/bin/env bash
# Quick start, part 2: installs dependencies, builds everything and runs every test:
#  1. the full build (preprocess, tools, tests) and ctest;
#  2. a runtime-only build with CGAL, Eigen and assimp made unfindable, and its tests;
#  3. install of the runtime package and a consumer project built with find_package(tetseg);
#  4. the Python package: pip install into a fresh virtual environment, pytest against it;
#  5. the loader fuzz target, briefly, when clang with libFuzzer is available.
# First of all, every C++ source must follow .clang-format (scripts/check-format.sh).
# The Python tests also run inside ctest (builds 1 and 2) against the build tree.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
jobs=${TETSEG_JOBS:-$(nproc)}
bash scripts/install-deps.sh
echo "== format (.clang-format)"
bash scripts/check-format.sh
# The Debian interpreter: python3-numpy, python3-pytest and pybind11 are installed for it (a
# python3 earlier on PATH, e.g. pyenv's, may lack them). TETSEG_BUILD_PYTHON=ON makes a
# missing dependency a configure error instead of a silently skipped package.
python=/usr/bin/python3
py_flags=(-DTETSEG_BUILD_PYTHON=ON "-DPython_EXECUTABLE=$python")

echo "== full build and tests"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_REQUIRE_TEST_DATA=ON \
  "${py_flags[@]}"
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== runtime-only build (no CGAL, Eigen, assimp)"
cmake -S . -B build-runtime-only -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_BUILD_PREPROCESS=OFF \
  -DTETSEG_REQUIRE_TEST_DATA=ON \
  -DCMAKE_DISABLE_FIND_PACKAGE_CGAL=ON -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON \
  -DCMAKE_DISABLE_FIND_PACKAGE_assimp=ON "${py_flags[@]}"
cmake --build build-runtime-only -j "$jobs"
ctest --test-dir build-runtime-only --output-on-failure -j "$jobs"

echo "== install and find_package(tetseg) consumer"
rm -rf build-install/prefix
cmake --install build-runtime-only --prefix "$root/build-install/prefix"
cmake -S tests/install-consumer -B build-install/consumer -G Ninja \
  -DCMAKE_PREFIX_PATH="$root/build-install/prefix"
cmake --build build-install/consumer
build-install/consumer/tetseg_consumer tests/golden/*.tetseg

echo "== Python package: pip install into a fresh virtual environment, pytest against it"
rm -rf build-venv
"$python" -m venv --system-site-packages build-venv   # NumPy and pytest from Debian
TETSEG_PIP_BUILD_DIR="$root/build-pip" TETSEG_JOBS="$jobs" \
  build-venv/bin/python -m pip install --no-build-isolation --no-index --no-deps ./python
# From outside the repository, without PYTHONPATH: the installed package is what is tested.
# Any pytest failure, or no test collected (exit 5), fails this script.
(cd build-venv && bin/python -c 'import sys, tetseg, tetseg.preprocess as p
assert tetseg.__file__.startswith(sys.prefix) and p.__file__.startswith(sys.prefix), tetseg.__file__' &&
  TETSEG_BIN_DIR="$root/build/tools" TETSEG_PYTHON_PREPROCESS=1 \
  bin/python -m pytest -q -p no:cacheprovider "$root/python/tests")

if command -v clang++ >/dev/null && [ -e /usr/lib/llvm-14/lib/clang/14.0.6/lib/linux/libclang_rt.fuzzer-x86_64.a ]; then
  echo "== loader fuzz target (60 s)"
  CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DTETSEG_BUILD_PREPROCESS=OFF -DTETSEG_BUILD_TOOLS=OFF -DTETSEG_BUILD_FUZZERS=ON
  cmake --build build-fuzz -j "$jobs" --target fuzz_load_asset
  mkdir -p build-fuzz/corpus
  cp tests/golden/*.tetseg build-fuzz/corpus/
  build-fuzz/tests/fuzz/fuzz_load_asset -max_total_time=60 build-fuzz/corpus
fi
echo "== all tests passed"
