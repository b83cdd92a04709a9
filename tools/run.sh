#!/usr/bin/env bash
# Builds batchcol and runs it. Usage:
#   tools/run.sh demo [args...]   build the CLI and run `batchcol demo [args...]`
#   tools/run.sh test             build everything and run the whole test suite (ctest)
#   tools/run.sh asan-test        same, built with AddressSanitizer + UBSan in build-asan/
# Missing Debian packages are installed with apt-get when running as root; otherwise the script prints the
# exact install command and stops. BATCHCOL_BUILD_DIR overrides the build folder (default: build/);
# BATCHCOL_CMAKE_ARGS adds CMake options (CI builds the demo with the optional peers switched off through it, and
# both builds with -DBATCHCOL_WERROR=ON: warnings are errors there).
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo_root"

usage() {
  echo "usage: tools/run.sh demo [batchcol demo args...] | test | asan-test" >&2
  exit 2
}

[[ $# -ge 1 ]] || usage
command="$1"
shift

required=(cmake g++ libeigen3-dev libtbb-dev libqhull-dev nlohmann-json3-dev libcli11-dev libassimp-dev
          libgtest-dev libbenchmark-dev libgmock-dev)
cross_check_peers=(libfcl-dev libbullet-dev libembree-dev)  # optional for the library, installed for the test suite
# The Python package and its pytest suite (Debian's /usr/bin/python3); optional for the library and the demo.
python_packages=(python3-dev pybind11-dev python3-numpy python3-pytest python3-distributed)

case "$command" in
  demo) packages=("${required[@]}") ;;
  test | asan-test) packages=("${required[@]}" "${cross_check_peers[@]}" "${python_packages[@]}") ;;
  *) usage ;;
esac

# Installs the Debian packages of "$@" that dpkg does not report as installed.
ensure_packages() {
  if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "run.sh: dpkg-query not found (not Debian?); make sure these are installed: $*" >&2
    return 0
  fi
  local missing=() pkg
  for pkg in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  if [[ ${#missing[@]} -eq 0 ]]; then
    echo "run.sh: all ${#packages[@]} required Debian packages are installed"
    return 0
  fi
  if [[ "$(id -u)" -ne 0 ]]; then
    echo "run.sh: missing Debian packages: ${missing[*]}" >&2
    echo "run.sh: install them with:" >&2
    echo "  sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  echo "run.sh: installing missing Debian packages: ${missing[*]}"
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y "${missing[@]}"
}

# configure_and_build <build dir> <target or "all"> <cmake -D options...>
configure_and_build() {
  local build_dir="$1" target="$2"
  shift 2
  echo "run.sh: configuring $build_dir ($*)"
  local extra=()
  read -r -a extra <<<"${BATCHCOL_CMAKE_ARGS:-}"
  cmake -S . -B "$build_dir" "$@" "${extra[@]}"
  echo "run.sh: building $target with $(nproc) jobs"
  cmake --build "$build_dir" --target "$target" -j"$(nproc)"
}

ensure_packages "${packages[@]}"

build_dir="${BATCHCOL_BUILD_DIR:-build}"
case "$command" in
  demo)
    configure_and_build "$build_dir" batchcol_cli -DCMAKE_BUILD_TYPE=Release
    echo "run.sh: running $build_dir/batchcol demo $*"
    exec "$build_dir/batchcol" demo "$@"
    ;;
  test)
    configure_and_build "$build_dir" all -DCMAKE_BUILD_TYPE=Release
    echo "run.sh: running the test suite"
    exec ctest --test-dir "$build_dir" --output-on-failure -j2
    ;;
  asan-test)
    configure_and_build build-asan all -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBATCHCOL_SANITIZE=ON
    echo "run.sh: running the test suite under AddressSanitizer + UBSan"
    exec ctest --test-dir build-asan --output-on-failure -j2
    ;;
esac
