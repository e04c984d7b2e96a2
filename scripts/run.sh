#!/usr/bin/env bash
# README quick start, command 1: set up, build, run the main job: a 5 v 5 match with the
# built-in agents (one simsoccer-agent process per robot over DDS, lockstep), 2 x 2 min halves.
# Writes runs/latest/ (summary.json, match.log, match.mp4, heatmap.png). Extra arguments go
# to `simsoccer match` (e.g. --half 600 for full halves, --seed N, --no-video).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
# Given twice, an option's last value counts: the user's --half wins. A run the user sends
# elsewhere with --out is not overwritten unless the user says --overwrite too.
defaults=(--half 120 --out runs/latest --overwrite)
for a in "$@"; do [ "$a" = --out ] && defaults=(--half 120); done
./build/apps/simsoccer match configs/match_5v5.yaml "${defaults[@]}" "$@"
