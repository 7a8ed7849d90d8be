#!/usr/bin/env bash
# Builds the two base images the Dockerfile names, from Debian alone, for
# machines that reach Debian's package mirrors but no container registry
# (docs/compare.md, "The container image, built"):
#   localhost/weft-debian:bookworm  Debian 12 (debootstrap --variant=minbase),
#                                   in place of debian:bookworm-slim;
#   localhost/weft-rust:bookworm    the same with build-essential and this
#                                   machine's Rust toolchain (rustup's
#                                   stable), in place of rust:1-bookworm.
# Then: podman build --build-arg RUNTIME_IMAGE=localhost/weft-debian:bookworm \
#         --build-arg RUST_IMAGE=localhost/weft-rust:bookworm -t weft .
# Needs root, podman (or buildah) and debootstrap (Debian packages).
set -euo pipefail
work=${WORK:-/tmp/weft-container-bases}
mirror=${MIRROR:-http://deb.debian.org/debian}
toolchain=${TOOLCHAIN:-$(rustc --print sysroot)}
rm -rf "$work"
mkdir -p "$work"
echo "bases: debootstrap bookworm (minbase) into $work/runtime"
debootstrap --variant=minbase bookworm "$work/runtime" "$mirror" >"$work/debootstrap-runtime.log"
tar -C "$work/runtime" -c . | podman import - localhost/weft-debian:bookworm
echo "bases: debootstrap bookworm with build-essential into $work/build"
debootstrap --variant=minbase --include=build-essential,ca-certificates,pkg-config \
  bookworm "$work/build" "$mirror" >"$work/debootstrap-build.log"
mkdir -p "$work/build/usr/local/rust"
# The toolchain's programs and libraries, not its documentation.
cp -a "$toolchain/bin" "$toolchain/lib" "$work/build/usr/local/rust/"
tar -C "$work/build" -c . | podman import \
  --change 'ENV PATH=/usr/local/rust/bin:/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
  --change 'ENV CARGO_HOME=/usr/local/cargo' \
  - localhost/weft-rust:bookworm
podman images --format '{{.Repository}}:{{.Tag}} {{.Size}}' | grep weft-
