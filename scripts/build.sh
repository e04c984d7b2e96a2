#!/usr/bin/env bash
# Installs what is missing, then configures and builds simsoccer in Release
# into build/ (incremental on later runs).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)"
