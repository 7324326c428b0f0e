#!/usr/bin/env bash
# trocar vs CasADi- and SymPy-generated C, wrenfold- and SymForce-generated Rust and Pinocchio, in one
# command (not part of CI):
#
#   bench/peers.sh            # everything: generate, check, criterion, callgrind, table
#   QUICK=1 bench/peers.sh    # shorter criterion runs
#   NO_PINOCCHIO=1 bench/peers.sh   # without Pinocchio (no pin wheels)
#
# 1. a virtual environment bench/.venv with casadi, sympy, wrenfold and symforce (PyPI), and Pinocchio's C++ from the
#    wheels pin (brings libpinocchio), cmeel-eigen and cmeel-urdfdom-headers (all pinned below);
# 2. bench/peers_gen.py writes the peers' C for J^r of the three presets, dia10_like's
#    FK + J^B_0i + J^r, and the Franka Panda's pose + body Jacobian of panda_link8 / panda_link7
#    (from trocar's shipped URDF), and g_0e + J^B_0i + J^r of two generic robots with an RCM
#    (bench/peers-harness/oblique7.toml: 7 oblique float axes, 2 explicit H rows, written by
#    `bench/chains.py --peers`; panda-link6-rcm.toml: the Panda constrained on panda_link6)
#    into bench/out/ (the presets are also measured against a frozen baseline, their generated
#    code and runtime surface of 2026-11-23 in bench/peers-harness/src/baseline, in the same runs);
#    bench/peers_rust_gen.py writes wrenfold's and SymForce's Rust for the same cases from the same
#    chains (bench/out/wrenfold_peers.rs, symforce_peers.rs: from q, and `eval_trig` given the
#    sines and cosines), which the harness compiles with its own flags (src/rust_peers.rs);
# 3. the harness bench/peers-harness (its own workspace, not a member of trocar's) compiles that C
#    with gcc -O3 -march=native (cc crate), and, when the venv has Pinocchio (feature
#    `pinocchio`), c/pinocchio_panda.cpp with g++ -O3 at the DEFAULT x86-64 ISA (no
#    -march=native: the wheel's libpinocchio is built for the default ISA, and a -march=native
#    (AVX-512) build of the calling code segfaults in Pinocchio's Model destructor on this machine);
#    checks every implementation against its f64 reference and each other (cargo test), and times
#    everything in one criterion run;
# 4. thread CPU time per evaluation (cg_driver CPUTIME=1), and for the 7- and 8-joint cases (the two
#    Panda cases, dia10_like, oblique7, the Panda with an RCM) the interleaved minimum wall time of
#    ours and the Rust peers taking turns (bin `interleave`, native and default ISA; in the listed
#    order and the reverse one, each IMPL's minimum over the two);
# 5. the Panda again with EVERYTHING at the default x86-64 ISA (Rust -C target-cpu=x86-64, C with
#    -march=x86-64; TROCAR_PEERS_DEFAULT_ISA=1), with dia10_like and oblique7: criterion and CPU
#    time, target/default-isa/;
# 6. callgrind counts instructions per evaluation: the default-ISA build of stage 5, and a native
#    build without AVX-512 (which valgrind 3.19 cannot decode);
# 7. bench/peers_table.py writes bench/out/table.md (and bench/out/panda.md).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="$here/out"
harness="$here/peers-harness"
mkdir -p "$out"

echo "== python environment" >&2
if [ ! -x "$here/.venv/bin/python" ]; then
  python3 -m venv "$here/.venv"
fi
"$here/.venv/bin/pip" install -q "casadi==3.8.2" "sympy==1.14.0" "wrenfold==0.5.0" "symforce==0.12.0" "symforce-sym==0.12.0"
# Pinocchio 4.1.0's C++ library and headers (pin -> libpinocchio, coal, cmeel-boost, cmeel-urdfdom),
# plus the headers its own headers include: Eigen 3.4.1 and urdfdom_headers 3.0.0 (the version its
# CMake config was built with: PINOCCHIO_URDFDOM_HEADERS_MAJOR_VERSION=3). Optional.
pin_features=""
if [ -z "${NO_PINOCCHIO:-}" ]; then
  if "$here/.venv/bin/pip" install -q "pin==4.1.0" "cmeel-eigen==3.4.1" "cmeel-urdfdom-headers==3.0.0"; then
    prefix="$("$here/.venv/bin/python" -c 'import os, sysconfig; print(os.path.join(sysconfig.get_paths()["purelib"], "cmeel.prefix"))')"
    if [ -f "$prefix/include/pinocchio/algorithm/frames.hpp" ] && [ -f "$prefix/include/eigen3/Eigen/Core" ]; then
      export TROCAR_PINOCCHIO_PREFIX="$prefix"
      pin_features="pinocchio"
      echo "== Pinocchio $("$here/.venv/bin/python" -c 'import pinocchio; print(pinocchio.__version__)') at $prefix" >&2
    fi
  fi
  [ -n "$pin_features" ] || echo "== Pinocchio not available: the Panda without it" >&2
fi

echo "== generate the peers' C" >&2
"$here/.venv/bin/python" "$here/peers_gen.py" "$out"
"$here/.venv/bin/python" "$here/peers_rust_gen.py" "$out"
python3 "$here/asm_counts.py" "$out" > /dev/null

echo "== machine" >&2
{ lscpu | grep -E 'Model name|^CPU\(s\)|MHz' ; gcc --version | head -1; g++ --version | head -1; rustc --version
  "$here/.venv/bin/pip" list 2>/dev/null | grep -iE '^(casadi|sympy|wrenfold|symforce|pin|libpinocchio|cmeel-eigen|cmeel-urdfdom-headers) ' || true
  uptime; } | tee "$out/machine.txt" >&2

# For the two Panda cases also: `ours_trig` (our `JointTrig::new` alone, one `sin_cos_array` of the
# 7 joints), and ours writing into the generated functions' own `(R, p)` and Jacobian in place, as
# the Rust peers write into the caller's arrays (the flat-buffer variants copy our pose once more).
trig_alone() {
  case "$1" in panda|panda_i) echo ours_trig ours_f64_in_place ours_f64_given_trig_in_place ;; esac
}

# `interleave BINARY CASE IMPL...` in the given order and in the reverse one, each IMPL's minimum
# over the two: in one order an IMPL ran about 1.75× slower for reasons of placement, not of
# its code (BENCHMARKS.md, "The fused functions on AVX-512, given the sines and cosines").
both_orders() {
  local bin="$1" case="$2" i
  shift 2
  local reversed=()
  for ((i = $#; i >= 1; i--)); do reversed+=("${!i}"); done
  { "$bin" "$case" 60 20000 "$@"; "$bin" "$case" 60 20000 "${reversed[@]}"; } |
    awk '{ if (!($1 in m) || $2 < m[$1]) m[$1] = $2; if (!($1 in o)) { o[$1] = ++n; k[n] = $1 } }
         END { for (i = 1; i <= n; i++) printf "%s %.2f\n", k[i], m[k[i]] }'
}

# At the default ISA, the fused cases also through the `_f64` entry points of the modules generated
# with `fma_at_run_time` (FMA chosen at run time), and the step cases with the pose in place.
fma_at_run_time() {
  case "$1" in
    panda_i) echo ours_f64_fma ours_f64_given_trig_fma ;;
    dia_zy|oblique7|panda_rcm) echo ours_f64_in_place ours_f64_given_trig_in_place ours_f64_fma ours_f64_given_trig_fma ;;
  esac
}

# Our generated code joins in when the generator's Builder is in this checkout (feature `ours`).
feature_list=""
ours_impls=""
if grep -qs "pub struct Builder" "$here/../codegen/src/builder.rs"; then
  feature_list="ours"
  ours_impls="ours_f64 ours_f64_given_trig ours_f32"
  echo "== trocar_codegen::Builder found: benchmarking our generated code too" >&2
else
  echo "== no trocar_codegen::Builder in this checkout: peers and numeric runtime only" >&2
fi
pin_impls=""
if [ -n "$pin_features" ]; then
  feature_list="${feature_list:+$feature_list,}$pin_features"
  pin_impls="pinocchio pinocchio_fk"
fi
features=()
[ -z "$feature_list" ] || features=(--features "$feature_list")
# Implementations measured per case (the numeric runtime has no panda_link8 frame).
rust_peers="wrenfold symforce wrenfold_given_trig symforce_given_trig"
impls_for() {
  case "$1" in
    panda) echo "noop trig_c_glibc casadi casadi_cse sympy rust_reference $ours_impls ${ours_impls:+ours_trig} $rust_peers ${ours_impls:+wrenfold_fed_trocar_sin_cos symforce_fed_trocar_sin_cos} $pin_impls" ;;
    panda_i) echo "noop trig_c_glibc casadi casadi_cse sympy numeric rust_reference $ours_impls ${ours_impls:+ours_trig} $rust_peers ${ours_impls:+wrenfold_fed_trocar_sin_cos symforce_fed_trocar_sin_cos} $pin_impls" ;;
    oblique7|panda_rcm) echo "casadi casadi_cse sympy numeric $ours_impls $rust_peers" ;;
    uni|bzy|bzx) echo "casadi casadi_cse sympy numeric rust_reference baseline $ours_impls $rust_peers" ;;
    *) echo "casadi casadi_cse sympy numeric rust_reference $ours_impls $rust_peers" ;;
  esac
}

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
for case in uni bzy bzx dia_zy panda panda_i oblique7 panda_rcm; do
  for impl in $(impls_for $case); do
    cpurun "$impl" "$case"
  done
done
echo "$cjson}" > "$out/cputime.json"

# The default-ISA stage always runs (wrenfold's and SymForce's Rust are always in the harness).
if true; then
  echo "== the Panda, dia10_like and oblique7 with everything at the default x86-64 ISA (Rust and C; Pinocchio always is)" >&2
  export TROCAR_PEERS_DEFAULT_ISA=1
  dflt=(env CARGO_TARGET_DIR="$harness/target/default-isa" RUSTFLAGS="-C target-cpu=x86-64")
  "${dflt[@]}" cargo test --release -q "${features[@]}"
  if [ -n "${QUICK:-}" ]; then
    "${dflt[@]}" cargo bench --bench peers "${features[@]}" -- '^(panda|panda_i|dia_zy|oblique7)/' --warm-up-time 1 --measurement-time 2
  else
    "${dflt[@]}" cargo bench --bench peers "${features[@]}" -- '^(panda|panda_i|dia_zy|oblique7)/' --warm-up-time 2 --measurement-time 5
  fi
  "${dflt[@]}" cargo build --release -q --bin cg_driver "${features[@]}"
  cjson="{"
  csep=""
  for case in panda panda_i dia_zy oblique7; do
    for impl in $(impls_for $case); do
      ns=$(CPUTIME=1 "$harness/target/default-isa/release/cg_driver" "$impl" "$case" 200000)
      cjson="$cjson$csep\"$impl/$case\": $ns"
      csep=", "
      echo "default ISA $impl/$case: $ns ns/eval (thread CPU time)" >&2
    done
  done
  echo "$cjson}" > "$out/cputime_default_isa.json"
  # Interleaved minimum wall time of the Panda cases (ours beside the Rust peers, in turns).
  if [[ "$feature_list" == *ours* ]]; then
    "${dflt[@]}" cargo build --release -q --bin interleave "${features[@]}"
    for case in panda panda_i dia_zy oblique7 panda_rcm; do
      # shellcheck disable=SC2046
      both_orders "$harness/target/default-isa/release/interleave" "$case" ours_f64 wrenfold symforce \
        ours_f64_given_trig wrenfold_given_trig symforce_given_trig $(trig_alone "$case") \
        $(fma_at_run_time "$case") | sed "s/^/$case /"
    done | tee "$out/interleave_default_isa.txt" >&2
  fi
  unset TROCAR_PEERS_DEFAULT_ISA
fi

if [[ "$feature_list" == *ours* ]]; then
  echo "== interleaved minimum, native" >&2
  cargo build --release -q --bin interleave "${features[@]}"
  for case in panda panda_i dia_zy oblique7 panda_rcm; do
    # shellcheck disable=SC2046
    both_orders "$harness/target/release/interleave" "$case" ours_f64 wrenfold symforce \
      ours_f64_given_trig wrenfold_given_trig symforce_given_trig $(trig_alone "$case") | sed "s/^/$case /"
  done | tee "$out/interleave_native.txt" >&2
fi

echo "== callgrind" >&2
n=10000
cgcount() { # driver impl case file -> instructions per iteration
  valgrind --tool=callgrind --toggle-collect='*measured_loop*' --callgrind-out-file="$4" \
    "$1" "$2" "$3" "$n" 2> /dev/null
  python3 -c "print($(grep -E '^(summary|totals):' "$4" | head -1 | awk '{print $2}') / $n)"
}
# At the default x86-64 ISA (the driver of the stage above; valgrind decodes all of it).
json="{"
sep=""
for case in - uni bzy bzx dia_zy panda panda_i oblique7 panda_rcm; do
  if [ "$case" = - ]; then impls=noop; else impls=$(impls_for $case); fi
  for impl in $impls; do
    c=$(cgcount "$harness/target/default-isa/release/cg_driver" "$impl" "$case" "$out/callgrind_default_isa.$impl.$case.out")
    json="$json$sep\"$impl/$case\": $c"
    sep=", "
    echo "default ISA $impl/$case: $c instructions/iteration" >&2
  done
done
echo "$json}" > "$out/callgrind_default_isa.json"
# Native, less AVX-512 (which valgrind 3.19 cannot decode).
export TROCAR_PEERS_NO_AVX512=1
CARGO_TARGET_DIR="$harness/target/cg" RUSTFLAGS="-C target-cpu=native -C target-feature=-avx512f" \
  cargo build --release -q --bin cg_driver "${features[@]}"
driver="$harness/target/cg/release/cg_driver"
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
for case in uni bzy bzx dia_zy panda panda_i oblique7 panda_rcm; do
  for impl in $(impls_for $case); do
    run "$impl" "$case"
  done
done
echo "$json}" > "$out/callgrind.json"

echo "== table" >&2
python3 "$here/peers_table.py" "$out" "$harness/target/criterion" "$harness/target/default-isa/criterion"
