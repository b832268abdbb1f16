#!/usr/bin/env bash
# Usage: cargo build --release -p ais-cli && tools/bench_gather.sh > table.md
# Time per frame and rays/s for each strategy x AIS mode on the default scene.
cd "$(dirname "$0")/.."
echo "| strategy | AIS | threads | render time (s) | rays/s | traced per gather | candidates per gather |"
echo "|---|---|---|---|---|---|---|"
for threads in 1 2; do
for strategy in uniform bsdf light mis; do
for ais in off aggressive conservative; do
  out=$(./target/release/ais render --quiet --resolution 320x180 --spp 4 --rays 16 --strategy $strategy --ais $ais --threads $threads -o "${TMPDIR:-/tmp}/bench_${strategy}_${ais}.exr" --no-preview)
  time=$(echo "$out" | awk '/render time/ {print $3}')
  rate=$(echo "$out" | awk '/^rays/ {print $(NF-2)}')
  traced=$(echo "$out" | sed -n 's/.*traced \([0-9.]*\), rejected.*/\1/p')
  cand=$(echo "$out" | sed -n 's/.*(\([0-9.]*\) per gather).*/\1/p')
  echo "| $strategy | $ais | $threads | $time | $rate M | $traced | $cand |"
done; done; done
