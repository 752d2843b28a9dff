#!/usr/bin/env bash
# Bakes one blob of each kind (a 2D set, a direction set, a BRDF sampler and an
# environment-map sampler, each small) with two builds of build-tool and compares
# the blobs byte for byte: the check that a refactoring changed no bits.
# Usage: scripts/same-bits.sh OLD_BUILD_TOOL NEW_BUILD_TOOL [OUT_DIR] [MAP]
set -euo pipefail
old=$1
new=$2
out=${3:-out/same-bits}
map=${4:-../shared/data/envmaps/studio.hdr}
bake() {
  local bt=$1 dir=$2
  "$bt" optimize --n 64 --epochs 300 --out "$dir/square" >/dev/null 2>&1
  "$bt" optimize --domain hemisphere --density brdf:0.3,60 --n 64 --epochs 300 \
    --out "$dir/hemisphere" >/dev/null 2>&1
  "$bt" bake --brdf --n 4 --steps 100 --out "$dir/brdf" >/dev/null 2>&1
  "$bt" bake --envmap "$map" --n 4 --steps 100 --out "$dir/envmap" >/dev/null 2>&1
}
rm -rf "$out"
bake "$old" "$out/old"
bake "$new" "$out/new"
status=0
for blob in square/set.nuld hemisphere/set.nuld brdf/brdf.nuld envmap/envmap.nuld; do
  if cmp -s "$out/old/$blob" "$out/new/$blob"; then
    echo "identical: $blob ($(wc -c <"$out/new/$blob") bytes)"
  else
    echo "DIFFERENT: $blob"
    status=1
  fi
done
exit $status
