#!/usr/bin/env bash
# Installs every build, test and run dependency of the mocap tracker from Debian 12's
# packages. Idempotent: packages already present are skipped, so a second run is quick.
# Usage (as root, or with sudo available):  bash deploy/install-deps.sh [--for test]
#   --for test: only what building and running the test suite needs (deploy/test.sh):
#   leaves out the tools used elsewhere only: clang and its runtime (deploy/fuzz.sh),
#   gnuplot (bench/evaluation's plots) and OpenCV (the bench/ baseline), which together
#   are about a fifth of the packages and most of the download.
set -euo pipefail

profile=all
case "${1:-}" in
  "") ;;
  --for)
    case "${2:-}" in
      test) profile=test ;;
      *) echo "install-deps.sh: --for takes 'test', got '${2:-}'" >&2; exit 2 ;;
    esac ;;
  *) echo "install-deps.sh: unknown argument '$1' (usage: install-deps.sh [--for test])" >&2; exit 2 ;;
esac

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git clang-format
  # core libraries
  libeigen3-dev libceres-dev libyaml-cpp-dev libcli11-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # shared-memory transport (iceoryx 2.0) and its ACL dependency
  iceoryx libiceoryx-posh-dev libiceoryx-hoofs-dev libacl1-dev
  # cameras: libcamera and the V4L2 headers
  libcamera-dev linux-libc-dev libv4l-dev
  # service integration and tools used by tests
  libsystemd-dev systemd liburdfdom-tools python3
  # header-only baseline of the ring-buffer benchmark
  libboost-dev
  # CRC-32 reference of the client tests
  zlib1g-dev
  # ecosystem outputs: ROS 2 over DDS (Cyclone DDS C API + idlc), the Foxglove WebSocket
  # server (Boost.Beast from libboost-dev, nlohmann-json)
  cyclonedds-dev cyclonedds-tools nlohmann-json3-dev
)
if [ "$profile" = all ]; then
  packages+=(
    # libFuzzer builds of deploy/fuzz.sh
    clang libclang-rt-14-dev
    # the plots of the evaluation script (bench/evaluation)
    gnuplot-nox
    # the OpenCV comparison baseline of bench/ (never linked by the product)
    libopencv-dev
  )
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-deps.sh: must run as root (or with sudo available)" >&2; exit 1; fi
fi

# Node.js and npm run only the test-only reference protocol clients (tests/, never the
# build or the tracker). Machines that already ship a Node.js with npm keep it; otherwise
# Debian's packages are added.
if ! command -v npm >/dev/null 2>&1; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps.sh: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps.sh: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
