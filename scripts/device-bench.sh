#!/usr/bin/env bash
# GPU benchmark on a machine with an NVIDIA GPU but possibly no Vulkan loader (the lent
# device machine): unpacks the loader .debs from .gl/ if present, points Vulkan at the
# NVIDIA driver, logs the GPU's clocks every 100 ms while `bench gpu` runs, and writes
# everything under $OUT (default: ./device-out).
#
#   scripts/device-bench.sh [QUADRECOMB_BINARY] [bench gpu arguments...]
#
# Prepare on a development machine (see docs/gpu.md): a release binary, stripped, in an
# ignored folder, and the loader: `apt-get download libvulkan1` into .gl/.
set -euo pipefail
bin=${1:-./target/release/quadrecomb}
shift || true
out=${OUT:-./device-out}
mkdir -p "$out"
if ! ldconfig -p | grep -q libvulkan.so.1; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$icd" ]; then
    export VK_DRIVER_FILES=$icd
fi
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.max.mem,memory.total \
    --format=csv | tee "$out/gpu.csv"
nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,power.draw,utilization.gpu \
    --format=csv -lms 100 >"$out/clocks.csv" 2>&1 &
smi=$!
trap 'kill $smi 2>/dev/null || true' EXIT
nproc
"$bin" bench gpu "$@" 2>&1 | tee "$out/bench-gpu.md"
