#!/usr/bin/env bash
# Memory bound of `cryoslosh run`: 10 million instances of a short lumped campaign (the MHTB tank,
# 3 dispersed inputs, 2 steps each). Prints the peak resident set size; the goal is < 1 GiB.
# Usage: bash tools/memory_10m.sh [OUT_DIR]   (needs /usr/bin/time: apt-get install time)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/cryoslosh_10m}
cargo build --release --quiet
/usr/bin/time -v ./target/release/cryoslosh run campaigns/mhtb_selfpress.toml --out "$out" \
  --instances 10000000 --set phases.0.duration_s=4 --set campaign.dt_s=2 2>&1 \
  | grep -E "instances|Maximum resident|Elapsed|drivers|peak pressure"
ls -l "$out"
