#!/usr/bin/env bash
# README quick start, command 1: set up, build, run the main job.
# Until the match runner lands, the main job is the physics scaling benchmark.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
./build/apps/simsoccer bench physics --csv build/bench_physics.csv "$@"
