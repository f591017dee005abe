#!/usr/bin/env bash
# Regenerates the "AFP programs (seed 000)" section of BENCHMARKS.md: seed 000's test parts and a
# 100-ply, 10,000-course panel, optimized and verified by towpath (release build).
# Extra arguments go to the benchmark: --runs N, --time-limit S, --big-time-limit S,
# --plies P, --courses C.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release -p towpath-nc --example afp_bench -- --write BENCHMARKS.md "$@"
