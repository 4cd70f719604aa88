#!/usr/bin/env bash
# Installs every Debian 12 package vkrt's build, tests, demo and benchmarks need. Idempotent: packages
# already present are not touched, and apt is not consulted at all when nothing is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config python3 clang-format ccache
  libvulkan-dev libvulkan1 vulkan-tools vulkan-validationlayers
  spirv-headers spirv-tools glslang-tools glslc
  llvm-15-dev libembree-dev libtbb-dev
  libgtest-dev libgmock-dev libbenchmark-dev libstb-dev libtinygltf-dev assimp-testmodels
  gfxreconstruct
  clang-14 libclang-rt-14-dev
  dpkg-dev file  # the Debian package: CPack's dpkg-shlibdeps (and `file`), dpkg-architecture in its check
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
echo "vkrt: installing ${missing[*]}" >&2
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
