#!/usr/bin/env bash
# Install what rest-embree needs on Debian/Ubuntu: Embree 3 and libclang (for the Embree
# backend's bindings) and a C compiler. Uses sudo when not root; does nothing when all is there.
set -euo pipefail

packages=(libembree-dev libclang-dev gcc g++ pkg-config libopenexr-dev openimageio-tools)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "setup: apt-get not found; install Embree 3 and libclang yourself (or build with --no-default-features --features cli)" >&2
    exit 1
  fi
  echo "setup: installing ${missing[*]}"
  # The lock timeout covers dpkg's locks, not the package lists' that update takes: another
  # apt-get updating at the same moment is waited out by trying again.
  for try in 1 2 3 4 5 6; do
    "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 update -qq && break
    [ "$try" -lt 6 ] || exit 1
    sleep 10
  done
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y -qq "${missing[@]}" >/dev/null
fi

if ! command -v cargo >/dev/null 2>&1; then
  echo "setup: Rust is not installed. Install Rust 1.87 or newer (https://rustup.rs), then run this again." >&2
  exit 1
fi

# `make test` checks the formatting and the lints too: rustup's default profile has both tools;
# a minimal one gets them here.
if command -v rustup >/dev/null 2>&1; then
  cargo fmt --version >/dev/null 2>&1 || rustup component add rustfmt
  cargo clippy --version >/dev/null 2>&1 || rustup component add clippy
fi
