#!/usr/bin/env bash
# trocar's numeric runtime vs Pinocchio on the Panda (g_0i + J^B_0i of panda_link7), in one process:
#   bench/numeric-pinocchio/run.sh
# Pinocchio's C++ from PyPI wheels in bench/.venv (pin 4.1.0, cmeel-eigen 3.4.1, cmeel-urdfdom-headers
# 3.0.0, as bench/peers.sh), c/pinocchio_panda.cpp of the peers harness built with g++ -O3 at the default
# x86-64 ISA (what the wheel is built for). Our Rust at target-cpu=native (the repository's
# .cargo/config.toml), then everything at the default ISA; callgrind counts at native less AVX-512
# (valgrind 3.19 does not decode it) and at the default ISA.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
bench="$(dirname "$here")"
[ -x "$bench/.venv/bin/python" ] || python3 -m venv "$bench/.venv"
"$bench/.venv/bin/pip" install -q "pin==4.1.0" "cmeel-eigen==3.4.1" "cmeel-urdfdom-headers==3.0.0"
export TROCAR_PINOCCHIO_PREFIX="$("$bench/.venv/bin/python" -c 'import os, sysconfig; print(os.path.join(sysconfig.get_paths()["purelib"], "cmeel.prefix"))')"
cd "$here"
lscpu | grep 'Model name'; uptime
cargo build --release -q
CARGO_TARGET_DIR="$here/target/default-isa" RUSTFLAGS="-C target-cpu=x86-64" cargo build --release -q
CARGO_TARGET_DIR="$here/target/cg" RUSTFLAGS="-C target-cpu=native -C target-feature=-avx512f" cargo build --release -q
bin=target/release/trocar-numeric-pinocchio
"$bin" check
echo "== native (Pinocchio at the default ISA)"; "$bin" time 60 20000
echo "== everything at the default ISA"; target/default-isa/release/trocar-numeric-pinocchio time 60 20000 new old pin
if command -v valgrind > /dev/null; then
  for d in cg default-isa; do
    for impl in new old pin; do
      f="$(mktemp)"
      valgrind --tool=callgrind --toggle-collect='*measured_loop*' --callgrind-out-file="$f" \
        "target/$d/release/trocar-numeric-pinocchio" cg "$impl" 10000 2> /dev/null
      echo "callgrind $d $impl: $(grep -E '^(summary|totals):' "$f" | head -1 | awk '{print $2 / 10000}') instructions/evaluation"
      rm -f "$f"
    done
  done
fi
uptime
