#!/usr/bin/env bash
# Set-up for radiosity: installs what the build needs and provides Embree 4.
#
#   ./setup.sh            install build dependencies and Embree 4 (idempotent, fast the second time)
#   ./setup.sh solve      ... then build and solve the built-in default scene into out/
#   ./setup.sh test       ... then run the test suite (cargo test --release)
#
# Embree 4: where the distribution ships it (Debian 13+, Ubuntu 24.04+) we use `libembree-dev`.
# Debian 12 ships only Embree 3, so there we unpack Intel's manylinux_2_28 build of Embree 4.4.0
# from the PyPI wheel `embreex4==4.4.0.post1` (sha256-pinned) into the git-ignored `.embree/`.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
ROOT=$(pwd)
EMBREE_LOCAL="$ROOT/.embree/lib"
WHEEL=embreex4-4.4.0.post1-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl
WHEEL_SHA256=ddc6887b38cc742a9ada3b04ce6157ce321c67325bfd9b758854ee0eabd74435

SUDO=""
if [ "$(id -u)" != 0 ] && command -v sudo >/dev/null 2>&1; then SUDO=sudo; fi

say() { echo "setup: $*" >&2; }

apt_updated=0
apt_install() {
  # Installs only the Debian packages that are missing; runs `apt-get update` once if needed.
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  if [ $apt_updated = 0 ]; then
    say "apt-get update"
    $SUDO apt-get update -qq >/dev/null
    apt_updated=1
  fi
  say "installing ${missing[*]}"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
}

have_system_embree4() {
  pkg-config --exists embree4 2>/dev/null && return 0
  for d in /usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib /usr/local/lib; do
    [ -e "$d/libembree4.so" ] && return 0
  done
  return 1
}

distro_has_embree4() {
  # libembree-dev is Embree 4 from major version 4 of the Debian package on.
  local v
  v=$(apt-cache policy libembree-dev 2>/dev/null | awk '/Candidate:/ {print $2}')
  case "$v" in 4.*|*:4.*) return 0 ;; *) return 1 ;; esac
}

install_embree_from_wheel() {
  [ -e "$EMBREE_LOCAL/libembree4.so" ] && return 0
  command -v python3 >/dev/null 2>&1 || apt_install python3 python3-pip
  apt_install unzip
  local tmp
  tmp=$(mktemp -d)
  say "downloading Embree 4.4.0 (PyPI wheel embreex4==4.4.0.post1)"
  python3 -m pip download -q --no-deps --only-binary=:all: \
    --python-version 3.11 --implementation cp --abi cp311 \
    --platform manylinux_2_28_x86_64 -d "$tmp" embreex4==4.4.0.post1
  echo "$WHEEL_SHA256  $tmp/$WHEEL" | sha256sum -c --quiet -
  mkdir -p "$EMBREE_LOCAL"
  unzip -q -o -j "$tmp/$WHEEL" 'embreex4.libs/*' -d "$EMBREE_LOCAL"
  (cd "$EMBREE_LOCAL" && ln -sf libembree4-*.so.4 libembree4.so)
  rm -rf "$tmp"
  say "Embree 4 in $EMBREE_LOCAL"
}

# 1. Build tools: libclang for embree4-sys' bindgen, pkg-config, a C compiler.
command -v cargo >/dev/null 2>&1 || { say "cargo not found: install Rust (rustup) first"; exit 1; }
apt_install libclang-dev pkg-config gcc

# 2. Embree 4.
if ! have_system_embree4; then
  if [ $apt_updated = 0 ] && ! apt-cache policy libembree-dev 2>/dev/null | grep -q Candidate; then
    $SUDO apt-get update -qq >/dev/null; apt_updated=1
  fi
  if distro_has_embree4; then
    apt_install libembree-dev
  else
    install_embree_from_wheel
  fi
fi

# 3. What was asked for.
case "${1:-}" in
  "") ;;
  solve) shift; cargo run --release --quiet -- solve "$@" ;;
  test) shift; cargo test --release "$@" ;;
  *) say "unknown command '$1' (expected: solve, test)"; exit 2 ;;
esac
