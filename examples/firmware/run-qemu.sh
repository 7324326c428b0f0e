#!/usr/bin/env bash
# The embedded examples on a Cortex-M4F under QEMU (board mps2-an386), checked against the host.
#
# Builds the two programs of examples/firmware/qemu for thumbv7em-none-eabihf (the firmware's DLS
# step on the generated dia10_like_zy kinematics; the Panda's runtime controller on its generated
# kinematics, DLS on the circle and the QP step with hard limits on the limits path), runs each
# under qemu-system-arm with semihosting and -icount, then compares every step with the host's
# f32 run of the same code (bit for bit) and the joints with the f64 run, and prints the largest
# differences, the instructions per step, the stack depth of a step and the flash and RAM of each
# program.
#
# Needs: rustup's thumbv7em-none-eabihf target (added here when missing), qemu-system-arm and,
# for the sizes, arm-none-eabi-size (Debian: qemu-system-arm binutils-arm-none-eabi).
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
out=target/qemu
target=thumbv7em-none-eabihf
if ! command -v qemu-system-arm >/dev/null; then
  echo "error: qemu-system-arm not found (Debian: apt-get install qemu-system-arm)" >&2
  exit 1
fi
if ! rustup target list --installed | grep -qx "$target"; then
  rustup target add "$target"
fi
mkdir -p "$out"
# The reference tables of the Panda's runs, from the scenarios' own paths (host).
cargo build -q --workspace --example qemu_references
"${CARGO_TARGET_DIR:-target}/debug/examples/qemu_references" "$out"
# The programs (the crate's .cargo/config.toml selects the target and the linker script).
(cd examples/firmware/qemu &&
  TROCAR_QEMU_REFERENCES="$root/$out" cargo build -q --release --target-dir "$root/target/thumb")
elf="$root/target/thumb/$target/release"
for program in firmware panda; do
  # -icount shift=6: 64 ns of virtual time per instruction, so SysTick counts instructions.
  timeout 600 qemu-system-arm -M mps2-an386 -nographic \
    -semihosting-config enable=on,target=native -icount shift=6 \
    -kernel "$elf/$program" > "$out/$program.txt"
  grep '^summary' "$out/$program.txt"
done
# Against the host: every step's rates bit for bit, the joints against the f64 run (both tests,
# in the workspace's own test build).
log="$out/check.txt"
if ! TROCAR_QEMU_FIRMWARE_OUTPUT="$root/$out/firmware.txt" \
  TROCAR_QEMU_PANDA_OUTPUT="$root/$out/panda.txt" TROCAR_QEMU_REFERENCES="$root/$out" \
  cargo test -q --workspace --test matches_qemu -- --ignored --nocapture > "$log" 2>&1; then
  cat "$log" >&2
  echo "error: the QEMU run differs from the host's (above)" >&2
  exit 1
fi
grep -E '^(firmware|panda) ' "$log"
# Flash (text + data) and static RAM (data + bss) of each program; the Panda's includes its
# reference tables (read-only data, not part of a controller).
if command -v arm-none-eabi-size >/dev/null; then
  tables=$(($(stat -c %s "$out/panda-circle.bin") + $(stat -c %s "$out/panda-limits.bin")))
  for program in firmware panda; do
    arm-none-eabi-size "$elf/$program" | awk -v p="$program" -v t="$tables" 'NR == 2 {
      extra = (p == "panda") ? sprintf(" (%d without its reference tables)", $1 + $2 - t) : ""
      printf "size %s flash %d bytes%s, static RAM %d bytes\n", p, $1 + $2, extra, $2 + $3 }'
  done
else
  echo "note: arm-none-eabi-size not found: sizes not measured (Debian: binutils-arm-none-eabi)"
fi
