#!/usr/bin/env bash
# Reproduces the 2D quality table of README.md: optimized sets (mean of 4 seeds)
# against the mean of 32 inverse-CDF-warped Owen-scrambled Sobol sets (plain
# Owen-Sobol for the uniform target), exact metrics from each run's report.json.
# Usage: scripts/quality-2d.sh [OUT_DIR]   (run from the repository root)
set -euo pipefail
out=${1:-out/quality-2d}
image=${NULD_IMAGE:-../shared/data/images/camera.png}
cargo build --release -q -p nuld-build-tool
bt=${NULD_BT:-target/release/build-tool}
runs=()
for n in 16 64 256 1024 2048; do runs+=("uniform $n"); done
for d in gaussian:0.5,0.5,0.15 quarter-disc "image:$image"; do
  for n in 64 256 1024; do runs+=("$d $n"); done
done
printf '| target | N | D2asd ours / baseline | L2* ours / baseline | D* ours / baseline | time/set |\n'
printf '|---|---:|---|---|---|---:|\n'
for r in "${runs[@]}"; do
  set -- $r
  dir="$out/$(echo "$1" | tr -c 'a-zA-Z0-9.\n' '_')-$2"
  "$bt" optimize --density "$1" --n "$2" --sets 4 --baseline-sets 32 --out "$dir" 2>/dev/null
  python3 - "$dir/report.json" <<'PY'
import json, sys, os
r = json.load(open(sys.argv[1]))
o, b = r["optimized_mean"], r["baseline_warped_owen_sobol_mean"]
name = r["density"]
if name.startswith("image:"):
    name = "image:" + os.path.basename(name[6:])
cell = lambda k: f"{o[k]:.3e} / {b[k]:.3e} ({o[k]/b[k]:.2f})"
print(f"| {name} | {r['n']} | {cell('asd')} | {cell('l2_star')} | {cell('star')} | {r['optimize_time_s']/r['sets']:.1f} s |")
PY
done
