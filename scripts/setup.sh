#!/usr/bin/env bash
# Installs the Debian packages blurcue needs (only those missing) and builds it (Release) into build/.
# Usage: scripts/setup.sh [--tests]    (as root, or with sudo available; --tests adds what only the tests need)
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake pkg-config
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-calib3d-dev libopencv-videoio-dev
  nlohmann-json3-dev libcli11-dev libsqlite3-dev libgtest-dev libexif-dev zlib1g-dev
  libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libglfw3-dev libglm-dev xvfb xauth xdotool
  python3-pandas python3-matplotlib python3-scipy python3-statsmodels python3-jsonschema python3-numpy python3-pil
  python3-questplus
  r-base-core r-cran-lme4 r-cran-lmertest r-cran-pbkrtest r-cran-emmeans
)
# --tests: what only the tests need besides - a real browser to open the report as a reader would, and an optimised
# BLAS/LAPACK for numpy: the capture tests solve their kernels by least squares (numpy.linalg.lstsq), 4 x faster on
# OpenBLAS than on the reference LAPACK that numpy gets otherwise. Debian switches libblas.so.3 and liblapack.so.3 to
# it; the single-threaded build, as ctest already runs two tests at once on two cores.
[ "${1:-}" = "--tests" ] && PACKAGES+=(chromium libopenblas0-serial)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
start=$SECONDS
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
  echo "setup: the packages took $((SECONDS - start)) s"
fi
start=$SECONDS

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > build.log 2>&1 || { cat build.log; exit 1; }
echo "setup: building (log in build.log)"
cmake --build build -j"$(nproc)" >> build.log 2>&1 || { tail -50 build.log; exit 1; }
echo "setup: built build/src/cli/blurcue in $((SECONDS - start)) s"
