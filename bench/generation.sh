#!/usr/bin/env bash
# Generation time and size on long and generic chains (BENCHMARKS.md, "Generation time").
#
#   bench/generation.sh [OUT_DIR]
#
# Writes the chains of bench/chains.py, then for each: `trocar generate` (release build) wall
# time and peak memory by /usr/bin/time, emitted lines, the operations the generated functions
# report, and `trocar verify --samples 200`. Prints a Markdown table.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$here/.."
out="${1:-$here/out/chains}"
cargo build --release -q -p trocar-cli --manifest-path "$root/Cargo.toml"
trocar="$root/target/release/trocar"
python3 "$here/chains.py" "$out"
echo "CPU: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| chain | joints | link | time | peak memory | emitted lines | operations (add + mul) | verify, 200 samples |"
echo "|---|---:|---:|---:|---:|---:|---:|---|"
for kind in a oblique; do
  for n in 8 9 12 16 20 24 28 30 32; do
    c="$kind$n"
    toml="$out/$c.toml"
    link=$(sed -n 's/^link = //p' "$toml")
    if ! /usr/bin/time -f "%e %M" -o "$out/$c.time" timeout 600 "$trocar" generate "$toml" -o "$out/$c.rs" 2>/dev/null; then
      echo "| $c | $n | $link | failed or > 600 s | | | | |"
      continue
    fi
    read -r secs kb < "$out/$c.time"
    lines=$(wc -l < "$out/$c.rs")
    ops=$(grep -o "Operations: [0-9]* add, [0-9]* mul" "$out/$c.rs" | grep -v "^$" | awk '{a+=$2; m+=$4} END {print a " + " m}')
    if "$trocar" verify "$toml" --samples 200 > "$out/$c.verify" 2>&1; then v="passed"; else v="**failed**"; fi
    printf "| %s | %d | %s | %.2f s | %d MB | %s | %s | %s |\n" "$c" "$n" "$link" "$secs" $((kb / 1024)) "$lines" "$ops" "$v"
  done
done
