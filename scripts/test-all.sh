#!/usr/bin/env bash
# The full test suite, installing what it needs: lavapipe (Mesa's software Vulkan, Debian
# package mesa-vulkan-drivers) for the GPU tests, Gmsh, meshio and VTK from PyPI for the checks that read our files, scipy for the statistics.
set -euo pipefail
cd "$(dirname "$0")/.."

sudo_if_needed() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

if ! ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1; then
  echo "== installing lavapipe (mesa-vulkan-drivers)"
  sudo_if_needed apt-get update -qq
  sudo_if_needed env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers
fi
# Python tools from PyPI: Gmsh (tests and data only), meshio and VTK (read our .msh/.vtu
# files), scipy (checks our statistics). Where the system's Python refuses pip installs
# (Debian and Ubuntu mark it externally managed, PEP 668) or has no pip, they go into a
# virtual environment under target/ that still sees the system's packages, put first on
# the PATH for the tests' python3.
venv="$PWD/target/test-venv"
if [ -x "$venv/bin/python3" ]; then export PATH="$venv/bin:$PATH"; fi
pip_install() {
  python3 -m pip install -q "$1" 2>/dev/null && return 0
  [ -x "$venv/bin/python3" ] && return 1
  echo "== this Python takes no pip installs: making a virtual environment in $venv"
  if ! python3 -m venv --system-site-packages "$venv" >/dev/null 2>&1 \
    || ! "$venv/bin/python3" -m pip --version >/dev/null 2>&1; then
    rm -rf "$venv"
    sudo_if_needed apt-get update -qq
    sudo_if_needed env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv python3-pip
    python3 -m venv --system-site-packages "$venv" || return 1
  fi
  export PATH="$venv/bin:$PATH"
  python3 -m pip install -q "$1"
}
for mod in gmsh==4.15.2 meshio==5.3.5 vtk==9.7.2 scipy==1.17.1; do
  if ! python3 -c "import ${mod%%==*}" >/dev/null 2>&1; then
    echo "== installing $mod from PyPI"
    pip_install "$mod" || echo "warning: could not install $mod; its checks will skip outside CI"
  fi
done

# GPU tests run on lavapipe: point the Vulkan loader at it when several drivers are installed
# (set VK_DRIVER_FILES yourself to test another driver). The tests log the adapter they use.
lvp=$(ls /usr/share/vulkan/icd.d/lvp_icd*.json 2>/dev/null | head -n 1 || true)
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -n "$lvp" ] && [ "$(ls /usr/share/vulkan/icd.d/*.json | wc -l)" -gt 1 ]; then
  export VK_DRIVER_FILES="$lvp"
fi
echo "== Vulkan drivers for the GPU tests: ${VK_DRIVER_FILES:-loader default}"
# Without a usable XDG_RUNTIME_DIR (CI, containers) Mesa's device-selection layer prints
# "error: XDG_RUNTIME_DIR is invalid ..." for every Vulkan instance the test process makes.
# The quadrecomb binary turns that layer off itself (src/main.rs); the test harness is
# another process, so do the same for it (the test that checks the binary's own switch
# removes this variable for the commands it runs).
if [ ! -d "${XDG_RUNTIME_DIR:-/nonexistent}" ] && [ -z "${NODEVICE_SELECT:-}" ]; then
  export NODEVICE_SELECT=1
fi

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy"
cargo clippy --all-targets -- -D warnings
echo "== cargo test (release)"
cargo test --release
# Again with debug assertions (the test profile): the search state's internal consistency
# checks and integer overflow checks, which the release build compiles out.
echo "== cargo test (debug assertions)"
cargo test
echo "== cargo bench (each benchmark once, as a test)"
cargo bench --bench benches -- --test
echo "== cargo doc"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --quiet
echo "== all checks passed"
