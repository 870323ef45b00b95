#!/bin/sh
# install-deps.sh -- make sure every Debian package lensmat builds or tests with is
# installed; apt-get only what is missing.  Idempotent: a second run only checks.
# Run by make (through the build/.deps stamp); safe to run by hand.
set -e
PKGS="gcc g++ make libreadline-dev libgsl-dev libembree-dev libgpiod-dev
      libopencv-dev clang libclang-rt-14-dev python3"
PKGS="$PKGS pkg-config zlib1g-dev"   # the imaging module: OpenCV flags, PNG data checks
PKGS="$PKGS gcc-aarch64-linux-gnu libc6-dev-arm64-cross"   # make check: arm64 compile
PKGS="$PKGS parallel"   # scripts/cornea-study.sh: GNU parallel fans the eyes out
PKGS="$PKGS rsync openssh-client"   # cornea-study.sh -S: parallel sends files with rsync over ssh
PKGS="$PKGS libfftw3-dev"   # the wave-optics engine: PSF and MTF transforms
PKGS="$PKGS libdouble-conversion-dev libhdf5-dev python3-numpy"   # trace outputs: shortest round-trip numbers, HDF5; .npy read back by NumPy in tests
PKGS="$PKGS libfmt-dev"   # trace outputs: Dragonbox shortest digits (header-only use)
PKGS="$PKGS python3-h5py"   # tests/t_69_trace_out.sh: HDF5 outputs read back by h5py
PKGS="$PKGS stress-ng"   # make check on a loaded machine (tests and the stop check)
missing=""
for p in $PKGS; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
        missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "install-deps: installing:$missing"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# shellcheck disable=SC2086
$SUDO apt-get install -y -qq --no-install-recommends $missing
