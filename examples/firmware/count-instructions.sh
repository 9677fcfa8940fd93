#!/usr/bin/env bash
# Counts the instructions of the generated compensation functions for a Cortex-M4F
# (thumbv7em-none-eabihf, release) from their disassembly, and the soft-float calls of the f64
# ones (the M4F's FPU is single precision). Prints one line per function. Needs llvm-objdump
# (the `llvm` package, or `rustup component add llvm-tools` and its bin directory on PATH).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
cargo build -q -p firmware-example --target thumbv7em-none-eabihf --release
lib="$root/target/thumbv7em-none-eabihf/release/libgenerated.rlib"
example="$root/target/thumbv7em-none-eabihf/release/libfirmware_example.rlib"
dis="$(mktemp)"
trap 'rm -f "$dis"' EXIT
llvm-objdump -dr --no-show-raw-insn "$lib" "$example" 2>/dev/null >"$dis"
printf '%-40s %12s %7s %10s\n' function instructions "fp div" "soft-float"
# One block per function: from its `<symbol>:` line to the next empty line.
awk '
  function flush() {
    if (name ~ /compensation/ && name !~ /_slice/ || name == "correct_pose")
      printf "%-40s %12d %7d %10d\n", name, n, div, soft
    name = ""
  }
  /^[0-9a-f]+ <.*>:$/ {
    flush(); name = $2; gsub(/[<>:]/, "", name); n = 0; div = 0; soft = 0; next
  }
  /R_ARM_/ { if ($0 ~ /R_ARM_THM_CALL[[:space:]]+__aeabi_d/) soft++; next }
  /^[[:space:]]+[0-9a-f]+:/ { n++; if ($0 ~ /vdiv/) div++; next }
  END { flush() }
' "$dis" | sed -E 's/_ZN9generated[0-9]+([a-z_0-9]+)[0-9]+([a-z_0-9]+)12compensation[0-9]+([a-z_0-9]+)17h[0-9a-f]+E/\1::\2::\3/; s/^([a-z_0-9:]+) +/\1 /' | awk '{printf "%-40s %12s %7s %10s\n", $1, $2, $3, $4}'
