#!/usr/bin/env bash
# Installs what building and testing raytree needs on a fresh Debian machine; quick when
# everything is already there. Usage: bash scripts/install-deps.sh
set -euo pipefail

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi

# System packages: a C toolchain for crates with build scripts; the X11/Wayland client
# libraries the window needs; Mesa's software Vulkan (lavapipe) so the viewer and its tests run
# without a GPU; Xvfb to run the window without a display; Slurm and munge for the one-node
# cluster that tests/cluster.rs starts (scripts/slurm/start-cluster.sh; no daemon is started
# here); Embree 3 for the peer bench's C harness, which the suite checks on a small scene.
need=()
for pkg in build-essential pkg-config curl ca-certificates \
  libvulkan1 mesa-vulkan-drivers libxkbcommon-x11-0 libx11-xcb1 libxcursor1 libxi6 libxrandr2 \
  libwayland-client0 libwayland-cursor0 libgl1 xvfb slurm-wlm munge libembree-dev; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}"
fi

# Rust: Debian's own cargo is too old for edition 2024, so use rustup's stable toolchain.
if ! command -v cargo >/dev/null 2>&1; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    export PATH="$HOME/.cargo/bin:$PATH"
  else
    curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
    export PATH="$HOME/.cargo/bin:$PATH"
  fi
fi
if command -v rustup >/dev/null 2>&1; then
  for comp in rustfmt clippy; do
    rustup component list --installed 2>/dev/null | grep -q "^$comp" || rustup component add "$comp"
  done
fi
