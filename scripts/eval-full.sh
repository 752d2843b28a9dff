#!/usr/bin/env bash
# Reproduces the evaluation results committed in docs/results (README "Results"):
# every figure at N = 4, 8, ..., 4096 with the paper's epochs (1000 in 2D, 5000 for
# directions). Realizations per figure (baseline / ours) are the paper's 128 / 16
# for Fig. 2 and fewer elsewhere, to fit 2 cores (about 2 h in all; see README).
# The cache under OUT/cache makes an interrupted run resume where it stopped.
# Usage: scripts/eval-full.sh [OUT_DIR] [DATA_DIR]   (run from the repository root)
set -euo pipefail
out=${1:-out/eval}
data=${2:-../shared/data}
cargo build --release -q -p nuld-build-tool
bt=${NULD_BT:-target/release/build-tool}
run() { "$bt" eval "$@" --out "$out" --max-n 4096 --data "$data"; }
run fig2 --realizations-baseline 128 --realizations-ours 16
run fig5 --realizations-baseline 32 --realizations-ours 4
run fig3 --realizations-baseline 32 --realizations-ours 4
run fig6 --realizations-baseline 8 --realizations-ours 4 --cap-star-caps 4096
run fig7 --realizations-baseline 16 --realizations-ours 4
# Copy the small outputs (not the cache) where the README links them:
#   cp "$out"/fig*.{csv,json,md,png} docs/results/
