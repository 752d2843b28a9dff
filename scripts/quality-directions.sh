#!/usr/bin/env bash
# Reproduces the direction quality table of README.md: optimized direction sets
# against Owen-scrambled Sobol sets warped by the target's standard sampler
# (equal-area map, cosine map, GGX-VNDF/diffuse mixture, envmap inverse CDF):
# uniform and cosine: mean of 2 optimized sets vs mean of 32 baseline sets;
# brdf and envmap (slower metrics): 1 optimized set vs mean of 8 baseline sets.
# Usage: scripts/quality-directions.sh [OUT_DIR] [FILTER]  (FILTER: a target prefix)
set -euo pipefail
out=${1:-out/quality-directions}
filter=${2:-}
envmap=${NULD_ENVMAP:-../shared/data/envmaps/courtyard.hdr}
cargo build --release -q -p nuld-build-tool
bt=${NULD_BT:-target/release/build-tool}
runs=()
for n in 64 256 1024 2048; do runs+=("sphere uniform $n"); done
for d in cosine brdf:0.3,45 "envmap:$envmap"; do
  dom=sphere; [ "$d" = cosine ] || [ "${d%%:*}" = brdf ] && dom=hemisphere
  for n in 64 256 1024; do runs+=("$dom $d $n"); done
done
printf '| domain | target | N | cap L2 ours / baseline | theta-uniform L2 ours / baseline | cap D* (lower bound) ours / baseline | time/set |\n'
printf '|---|---|---:|---|---|---|---:|\n'
for r in "${runs[@]}"; do
  set -- $r
  case "$2" in "$filter"*) ;; *) continue ;; esac
  dir="$out/$1-$(echo "$2" | tr -c 'a-zA-Z0-9.\n' '_')-$3"
  case "$2" in uniform|cosine) sets=(--sets 2 --baseline-sets 32) ;; *) sets=(--sets 1 --baseline-sets 8) ;; esac
  "$bt" optimize --domain "$1" --density "$2" --n "$3" "${sets[@]}" --out "$dir" 2>/dev/null
  python3 - "$dir/report.json" <<'PY'
import json, sys, os
r = json.load(open(sys.argv[1]))
o, b = r["optimized_mean"], r["baseline_warped_owen_sobol_mean"]
name = r["density"]
if name.startswith("envmap:"):
    name = "envmap:" + os.path.basename(name[7:])
cell = lambda k: f"{o[k]:.3e} / {b[k]:.3e} ({o[k]/b[k]:.2f})"
print(f"| {r['domain']} | {name} | {r['n']} | {cell('cap_l2')} | {cell('cap_l2_theta')} | {cell('cap_star_lower_bound')} | {r['optimize_time_s']/r['sets']:.1f} s |")
PY
done
