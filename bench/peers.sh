#!/usr/bin/env bash
# trocar vs CasADi- and SymPy-generated C, in one command (not part of CI):
#
#   bench/peers.sh            # everything: generate, check, criterion, callgrind, table
#   QUICK=1 bench/peers.sh    # shorter criterion runs
#
# 1. a virtual environment bench/.venv with casadi and sympy (PyPI);
# 2. bench/peers_gen.py writes the peers' C for J^r of the three presets and dia10_like's
#    FK + J^B_0i + J^r into bench/out/;
# 3. the harness bench/peers-harness (its own workspace, not a member of trocar's) compiles that C
#    with gcc -O3 -march=native (cc crate), checks every peer against its f64 reference
#    (cargo test), and times everything in one criterion run;
# 4. callgrind counts instructions per evaluation (a build without AVX-512, which valgrind 3.19
#    cannot decode);
# 5. bench/peers_table.py writes bench/out/table.md.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="$here/out"
harness="$here/peers-harness"
mkdir -p "$out"

echo "== python environment" >&2
if [ ! -x "$here/.venv/bin/python" ]; then
  python3 -m venv "$here/.venv"
fi
"$here/.venv/bin/pip" install -q "casadi==3.8.2" "sympy==1.14.0"

echo "== generate the peers' C" >&2
"$here/.venv/bin/python" "$here/peers_gen.py" "$out"
python3 "$here/asm_counts.py" "$out" > /dev/null

echo "== machine" >&2
{ lscpu | grep -E 'Model name|^CPU\(s\)|MHz' ; gcc --version | head -1; rustc --version; uptime; } | tee "$out/machine.txt" >&2

# Our generated code joins in when the generator's Builder is in this checkout (feature `ours`).
features=()
ours_impls=""
if grep -qs "pub struct Builder" "$here/../codegen/src/builder.rs"; then
  features=(--features ours)
  ours_impls="ours_f64 ours_f64_given_trig ours_f32"
  echo "== trocar_codegen::Builder found: benchmarking our generated code too" >&2
else
  echo "== no trocar_codegen::Builder in this checkout: peers and numeric runtime only" >&2
fi

cd "$harness"
echo "== check the peers (and ours) against the f64 reference" >&2
cargo test --release -q "${features[@]}"

echo "== criterion" >&2
if [ -n "${QUICK:-}" ]; then
  cargo bench --bench peers "${features[@]}" -- --warm-up-time 1 --measurement-time 2
else
  cargo bench --bench peers "${features[@]}" -- --warm-up-time 2 --measurement-time 5
fi

echo "== thread CPU time (robust to other load on the machine)" >&2
cargo build --release -q --bin cg_driver "${features[@]}"
cjson="{"
csep=""
cpurun() { # impl case
  local ns
  ns=$(CPUTIME=1 "$harness/target/release/cg_driver" "$1" "$2" 200000)
  cjson="$cjson$csep\"$1/$2\": $ns"
  csep=", "
  echo "$1/$2: $ns ns/eval (thread CPU time)" >&2
}
for impl in noop trig_c_glibc trig_std_f64 trig_fast_f64 trig_libm_f64 trig_std_f32 trig_fast_f32 trig_libm_f32; do
  cpurun "$impl" -
done
for case in uni bzy bzx dia_zy; do
  for impl in casadi casadi_cse sympy numeric rust_reference $ours_impls; do
    cpurun "$impl" "$case"
  done
done
echo "$cjson}" > "$out/cputime.json"

echo "== callgrind" >&2
export TROCAR_PEERS_NO_AVX512=1
CARGO_TARGET_DIR="$harness/target/cg" RUSTFLAGS="-C target-cpu=native -C target-feature=-avx512f" \
  cargo build --release -q --bin cg_driver "${features[@]}"
driver="$harness/target/cg/release/cg_driver"
n=10000
json="{"
sep=""
run() { # impl case
  local f="$out/callgrind.$1.$2.out"
  valgrind --tool=callgrind --toggle-collect='*measured_loop*' --callgrind-out-file="$f" \
    "$driver" "$1" "$2" "$n" 2> /dev/null
  local total
  total=$(grep -E '^(summary|totals):' "$f" | head -1 | awk '{print $2}')
  json="$json$sep\"$1/$2\": $(python3 -c "print($total / $n)")"
  sep=", "
  echo "$1/$2: $(python3 -c "print($total / $n)") instructions/iteration" >&2
}
for impl in noop trig_c_glibc trig_std_f64 trig_fast_f64 trig_libm_f64 trig_std_f32 trig_fast_f32 trig_libm_f32; do
  run "$impl" -
done
for case in uni bzy bzx dia_zy; do
  for impl in casadi casadi_cse sympy numeric rust_reference $ours_impls; do
    run "$impl" "$case"
  done
done
echo "$json}" > "$out/callgrind.json"

echo "== table" >&2
python3 "$here/peers_table.py" "$out" "$harness/target/criterion"
