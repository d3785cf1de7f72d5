# Shared set-up of scripts/demo and scripts/test (sourced, not run): installs missing
# Debian packages with apt, then configures and builds RTfact (Release) into build/.
set -euo pipefail

RTFACT_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${RTFACT_BUILD_DIR:-$RTFACT_ROOT/build}"

RTFACT_PACKAGES=(
  cmake make g++ pkg-config
  libtbb-dev libopenimageio-dev openimageio-tools
  libpcl-dev libvtk9-dev libopenvdb-dev libembree-dev
  libgtest-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev
  pybind11-dev python3-dev python3-numpy python3-pytest
  libboost-dev libturbojpeg0-dev chromium chromium-driver python3-selenium
  libopenmpi-dev openmpi-bin
  xvfb xauth libx11-dev
)

rtfact_install_packages() {
  local missing=()
  for p in "${RTFACT_PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    echo "setup: all packages present"
    return
  fi
  echo "setup: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# rtfact_build [extra cmake args...]
rtfact_build() {
  local jobs
  jobs="$(nproc 2>/dev/null || echo 2)"
  mkdir -p "$BUILD_DIR"
  cmake -S "$RTFACT_ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "$@" >"$BUILD_DIR/configure.log" 2>&1 || {
    cat "$BUILD_DIR/configure.log"
    echo "setup: cmake configure failed" >&2
    return 1
  }
  cmake --build "$BUILD_DIR" -j "$jobs"
}
