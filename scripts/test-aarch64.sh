#!/usr/bin/env bash
# The tracer's tests on 64-bit ARM (aarch64), cross-compiled on an x86-64 Debian machine and
# run under qemu-user: the library's unit tests, the packet traversal's bit-identity tests (on
# ARM the 4-wide node test runs on glam's NEON vectors and there is no AVX2 path), the renders
# against the golden images, and the trace tests. The headless core only (no window, no
# lab), so no C++ cross build is needed. Installs the cross toolchain and qemu itself; about
# 5 minutes on 2 cores.
# Not part of scripts/test.sh: it downloads a cross toolchain and rust-std for a second target.
# Usage: bash scripts/test-aarch64.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/install-deps.sh
export PATH="$HOME/.cargo/bin:$PATH"

need=()
for pkg in qemu-user gcc-aarch64-linux-gnu libc6-dev-arm64-cross; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}"
fi
rustup target list --installed | grep -q '^aarch64-unknown-linux-gnu$' ||
  rustup target add aarch64-unknown-linux-gnu

export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER="qemu-aarch64 -L /usr/aarch64-linux-gnu"
echo "== cargo clippy (aarch64, headless core)"
cargo clippy --release --target aarch64-unknown-linux-gnu --no-default-features --locked -- -D warnings
echo "== cargo test (aarch64 under qemu: unit tests, packets, render, trace)"
cargo test --release --target aarch64-unknown-linux-gnu --no-default-features --locked \
  --lib --test packets --test render --test trace
