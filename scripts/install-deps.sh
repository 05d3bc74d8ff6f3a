#!/usr/bin/env bash
# Installs every Debian package this project needs to build, test and run.
# Idempotent: apt-get skips what is already installed. Needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libgtest-dev libgmock-dev googletest
  libmrpt-dev mrpt-apps libnanoflann-dev
  libwxgtk3.2-dev  # the viewer names MRPT's window thread (WxSubsystem.h includes wxWidgets)
  libeigen3-dev
  libopencv-dev
  libdeflate-dev  # reads MRPT's external depth files faster than zlib's stream
  libceres-dev libsuitesparse-dev
  libopenni2-dev
  liboctomap-dev
  libpcl-dev
  nlohmann-json3-dev  # the apps' JSON summaries
  libgl1-mesa-dri libegl-mesa0 libegl1
  xvfb x11-utils imagemagick xdotool  # viewers tested under a virtual X server (xdotool: keys)
  python3
)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
