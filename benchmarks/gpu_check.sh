#!/usr/bin/env bash
# On a machine with an NVIDIA GPU, in one call (under 10 minutes): install the GPU extra if Warp is
# missing (from benchmarks/wheels/ when that folder holds the wheels: a device machine may have
# no network), run the GPU backend's tests on the device, the kernel bench (kept as
# benchmarks/gpu_bench.json with the device's name), and the Lamb plate case on both backends,
# then print one table comparing them. Record the numbers in benchmarks/RESULTS.md.
#
#   bash benchmarks/gpu_check.sh [CASE]        (default cases/lamb_plate.yaml)
set -euo pipefail
cd "$(dirname "$0")/.."
case_file="${1:-cases/lamb_plate.yaml}"
out="${GPU_CHECK_OUT:-/tmp/peridyn-gpu-check}"
export PYTHONPATH="$PWD/src${PYTHONPATH:+:$PYTHONPATH}"
unset PERIDYN_GPU_ON_CPU

if ! python -c "import warp" 2>/dev/null; then
    if [ -d benchmarks/wheels ]; then
        python -m pip install --no-index --find-links benchmarks/wheels "warp-lang>=1.19"
    else
        python -m pip install -e ".[gpu]"
    fi
fi
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true
date -u

echo "== GPU tests on the device"
timeout 200 python -m pytest -q -p no:cacheprovider tests/gpu

echo "== kernel bench on the device"
timeout 100 peridyn bench --backend gpu --json > benchmarks/gpu_bench.json
python - <<'PY'
import json
from peridyn.jobs.bench_gpu import format_gpu_table
print(format_gpu_table(json.load(open("benchmarks/gpu_bench.json"))))
PY

echo "== $case_file on both backends"
rm -rf "$out"
common=(--json --no-progress --overwrite --set output.plots=false --set output.vtu=false)
timeout 200 peridyn run "$case_file" "${common[@]}" -o "$out/cpu" > "$out-cpu.json"
timeout 80 peridyn run "$case_file" --backend gpu "${common[@]}" -o "$out/gpu" > "$out-gpu.json"
python benchmarks/gpu_compare.py "$out/cpu" "$out/gpu"
