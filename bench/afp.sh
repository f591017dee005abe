#!/usr/bin/env bash
# Regenerates the "AFP programs (Doherty et al. 2022)" section of BENCHMARKS.md: Doherty et al.'s test parts and a
# 100-ply, 10,000-course panel, optimized and verified by towpath (release build).
# Extra arguments go to the benchmark: --runs N, --time-limit S, --big-time-limit S,
# --plies P, --courses C.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release -p towpath-bench -- afp --write BENCHMARKS.md "$@"
