#!/usr/bin/env bash
# README quick start, command 2: set up, build, run the whole test suite, then build the
# fuzz targets with clang (ASan, UBSan) and run each for 20 s with the unit and net tests under
# the same sanitizers (build-fuzz/), then the multi-threaded parts' tests under
# ThreadSanitizer (build-tsan/).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
# Twice as many tests as cores: most of the long ones wait on other processes (agents in
# lockstep, DDS discovery, a stopped agent), which keeps 2 cores about 60 % busy at -j 2.
ctest --test-dir build --output-on-failure -j "$((2 * $(nproc)))"
bash scripts/fuzz.sh 20
bash scripts/tsan.sh
