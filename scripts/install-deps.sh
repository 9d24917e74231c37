#!/usr/bin/env bash
# Installs every Debian 12 package brdf-factor needs to build, test and make its
# reports. Idempotent: packages already present are not touched, and apt is only
# called when something is missing. Run as root (or with sudo available).
#   scripts/install-deps.sh           what the default build, tests and reports need
#   scripts/install-deps.sh --fuzz    also clang and its libFuzzer/sanitizer
#                                     runtimes, for fuzz/run.sh (build-fuzz/)
# Then ESLint (the viewer's JavaScript linter, scripts/lint-js.sh) from npm into
# scripts/eslint/node_modules, pinned by scripts/eslint/package-lock.json; skipped
# when that lock is already installed, so it works offline once installed.
# The sanitizer test build (scripts/test-sanitize.sh) uses gcc's ASan/UBSan
# runtimes (libasan8, libubsan1), which build-essential already brings.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev          # linear algebra (3.4)
  libceres-dev           # nonlinear least squares (2.1)
  libsuitesparse-dev     # CHOLMOD, the sparse fit's supernodal Cholesky (also a libceres-dev dependency)
  libopenexr-dev         # EXR textures and environment maps (3.1)
  libpng-dev             # PNG previews and renders (1.6)
  libnlopt-cxx-dev       # alternative optimizers (2.7)
  catch2                 # tests (2.13)
  libtomlplusplus-dev    # TOML configs
  nlohmann-json3-dev     # JSON sidecars and manifests
  libcli11-dev           # command-line parsing
  glslang-tools          # compiles the generated GLSL in a test
  libegl-dev libgl-dev libopengl-dev  # EGL/OpenGL headers for the GLSL test helper
  libegl-mesa0 libgl1-mesa-dri        # Mesa's surfaceless EGL and llvmpipe: the generated GLSL runs on the CPU
  python3-matplotlib     # plots in experiment reports
  pybind11-dev           # the Python module (python/), built for /usr/bin/python3
  python3-dev            # Python headers and libpython for the module
  python3-numpy          # arrays in and out of the Python module
  python3-scipy          # the scipy peer of `bench fit` (scripts/bench-peer.py, docs/speed.md)
  python3-pytest         # the Python module's tests (python/tests/)
  python3-pip python3-setuptools python3-wheel python3-venv  # `pip install .` of the module (docs/python.md)
  git                    # the build's commit in run records (a runner test needs it)
  util-linux             # unshare: a test mounts a folder read-only (CI runs as root)
  chromium               # headless test of report.html's WebGL2 viewer
)
# node and npm run ESLint (below). A node from another apt source may bring its
# own npm (Debian's npm package conflicts with it): only when no npm is found
# are Debian's nodejs and npm asked for.
if ! command -v npm > /dev/null 2>&1; then PACKAGES+=(nodejs npm); fi
case "${1:-}" in
  "") ;;
  --fuzz) PACKAGES+=(
    clang                  # clang++ 14 (fuzz/run.sh configures with CC=clang CXX=clang++)
    libclang-rt-14-dev     # libFuzzer, ASan and UBSan runtimes for clang 14
  ) ;;
  *) echo "install-deps: unknown argument '$1' (expected nothing or --fuzz)" >&2; exit 2 ;;
esac

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
else
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# ESLint: `npm ci` installs exactly the lock; the stamp (a copy of the lock
# installed) makes a second run a no-op that needs no network.
eslint_dir="$(cd "$(dirname "$0")" && pwd)/eslint"
stamp="$eslint_dir/node_modules/.bf-installed-lock.json"
if [ -x "$eslint_dir/node_modules/.bin/eslint" ] && cmp -s "$eslint_dir/package-lock.json" "$stamp"; then
  echo "install-deps: ESLint present ($eslint_dir/node_modules)"
else
  echo "install-deps: npm ci in $eslint_dir"
  (cd "$eslint_dir" && npm ci --no-audit --no-fund --loglevel=error)
  cp "$eslint_dir/package-lock.json" "$stamp"
fi
