#!/usr/bin/env bash
# The whole test suite, as CI runs it: formatting, lints, every test (in release: the tests
# trace many rays), and the docs. Installs what it needs first.
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/install-deps.sh
export PATH="$HOME/.cargo/bin:$PATH"
# The viewer tests render through wgpu on Mesa's software Vulkan (no GPU, no display needed).
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy"
cargo clippy --release --all-targets --locked -- -D warnings
# The headless core: without the `viewer` and `lab` features the library and the CLI must
# build with no window library, so the compiler keeps egui, eframe and wgpu out of the core;
# the tests and benches that need them say so (`required-features` in Cargo.toml).
echo "== cargo clippy --no-default-features (headless core and CLI)"
cargo clippy --release --all-targets --no-default-features --locked -- -D warnings
echo "== cargo test (release)"
cargo test --release --locked
# The peer bench's Embree harness traces the same rays as raytree and gives its image, in
# every configuration (a small scene, one round: a check of the harness, not a measurement).
echo "== the Embree peer harness (cargo bench --bench peer -- --check)"
cargo bench --locked --bench peer -- --check --sizes 2000 --runs 1 --warmup 0 --frames 2 \
  --peer-config all
echo "== cargo doc"
RUSTDOCFLAGS="-D warnings" cargo doc --release --no-deps --locked --quiet
