#!/usr/bin/env bash
# Installs the Debian 12 packages simsoccer needs (only the missing ones),
# non-interactively and idempotently. Safe to run again.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libbullet-dev                 # physics (Bullet 3.24, single precision)
  libeigen3-dev                 # maths
  libopencv-dev                 # images, video, plots
  libyaml-cpp-dev               # configs
  zlib1g-dev                    # match logs (deflated blocks)
  cyclonedds-dev cyclonedds-tools  # DDS transport and its IDL compiler (idlc)
  libmsgpack-cxx-dev            # LoLA actuator maps (parsed only: sensor maps are hand-encoded)
  libssl-dev                    # robot keys (HMAC-SHA256), DDS Security credentials
  nlohmann-json3-dev            # Booster SDK endpoint: the JSON of its RPC requests and answers
  libfastrtps-dev               # tests: a Booster SDK client on Fast DDS, the middleware the SDK bundles
  bubblewrap                    # lola-run: a private /tmp/robocup per team binary
  iproute2                      # lola-run --net: the field network (bridge, namespaces)
  libgtest-dev libgmock-dev     # tests
  clang libclang-rt-14-dev      # fuzzing: libFuzzer, AddressSanitizer, UBSan (scripts/fuzz.sh)
  libegl-dev libgl-dev libopengl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri  # off-screen EGL rendering (Mesa llvmpipe on CPU)
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "setup: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
