#!/usr/bin/env bash
# trocar's QP solver against DAQP and OSQP on the QPs of the scene `three-ports` and of the
# Panda's QP control step in `panda-laparoscope-limits` (not part of CI):
#
#   bench/qp-peers/run.sh              # the default x86-64 instruction set for both
#   QP_PEERS_NATIVE=1 bench/qp-peers/run.sh   # -C target-cpu=native and -march=native
#
# Fetches DAQP's C sources from its PyPI sdist (fetch-daqp.sh), builds OSQP with the `osqp`
# crate (needs cmake), and prints each solver's time per solve and its optimum's distance from
# trocar's (src/main.rs).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
"$here/fetch-daqp.sh"
cd "$here"
if [ -n "${QP_PEERS_NATIVE:-}" ]; then
    export RUSTFLAGS="${RUSTFLAGS:-} -C target-cpu=native"
    export CARGO_TARGET_DIR="$here/target/native"
fi
cargo run --release --quiet
