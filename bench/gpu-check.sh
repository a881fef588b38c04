#!/usr/bin/env bash
# The GPU check, for a machine with an NVIDIA GPU (the device tool's), in one go, under 8 minutes:
#   1. builds the benchmark without the gRPC server (cmake -DDOWNPOUR_BUILD_SERVER=OFF), unless
#      DOWNPOUR_BENCH names a built downpour-bench or build-gpu/ already holds one;
#   2. checks that the renderer the server would pick (--renderer auto) is NVIDIA's EGL device;
#   3. prints the benchmark's JSON for COCKPIT at 1920x1080 and 3840x2160, at 240 frames a second
#      of simulation (the goal: >= 240 fps delivered at 1080p for the full scene), and a summary.
# Exit status: 0 when the GPU was picked (whatever the rates), 3 when it was not, 2 on a failed
# build. Nothing here is run by CI.
set -euo pipefail
cd "$(dirname "$0")/.."
START=$(date +%s)
BUILD=${DOWNPOUR_GPU_BUILD_DIR:-build-gpu}
BENCH=${DOWNPOUR_BENCH:-$BUILD/downpour-bench}
OUT=${OUT:-$BUILD}
elapsed() { echo "$(($(date +%s) - START)) s"; }

echo "== machine"
nproc
nvidia-smi -L 2>/dev/null || echo "nvidia-smi: not found"
ls /usr/share/glvnd/egl_vendor.d/ 2>/dev/null || true

if [ ! -x "$BENCH" ]; then
  echo "== build ($(elapsed))"
  missing=()
  for tool in cmake ninja g++ pkg-config; do command -v "$tool" >/dev/null || missing+=("$tool"); done
  if ((${#missing[@]})); then
    echo "missing build tools: ${missing[*]}; trying apt-get (this machine may be offline)"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      cmake ninja-build g++ pkg-config libturbojpeg0-dev libspdlog-dev libglm-dev libcli11-dev \
      nlohmann-json3-dev libpng-dev libpugixml-dev libegl-dev libgl-dev libopengl-dev >/dev/null || {
      echo "cannot install the build tools: copy a built downpour-bench here (DOWNPOUR_BENCH)"
      exit 2
    }
  fi
  cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DDOWNPOUR_BUILD_SERVER=OFF \
    -DDOWNPOUR_BUILD_TESTS=OFF >/dev/null || exit 2
  cmake --build "$BUILD" --target downpour-bench -j "$(nproc)" || exit 2
  BENCH=$BUILD/downpour-bench
fi

echo "== renderer ($(elapsed))"
if ! "$BENCH" --renderer auto --check-renderer | tee "$OUT/gpu-renderer.json"; then
  echo "FAIL: the server would not pick a GPU's EGL device here"
  exit 3
fi
if ! grep -qi nvidia "$OUT/gpu-renderer.json"; then
  echo "FAIL: the EGL device picked is not NVIDIA's"
  exit 3
fi

echo "== benchmark ($(elapsed))"
threads=$(nproc)
encoders=$((threads > 8 ? 8 : threads / 2 > 0 ? threads / 2 : 1))
timeout 360 "$BENCH" --renderer device --sizes 1920x1080 3840x2160 --fps 240 --frames 480 \
  --realtime-seconds 3 --encoder-threads "$encoders" --no-demo >"$OUT/gpu-bench.json"
cat "$OUT/gpu-bench.json"

echo "== summary ($(elapsed))"
python3 - "$OUT/gpu-bench.json" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
for r in d["results"]:
    s = r["stages"]
    print(f'{r["size"]}: {r["pipelined"]["fps"]:.0f} fps pipelined, {r["serial"]["fps"]:.0f} serial; '
          f'render thread {s["render_thread_ms"]:.2f} ms, step {s["step_ms"]:.2f} ms '
          f'(water {s["water_step_ms"]:.2f}, map {s["water_map_ms"]:.2f}), encode {s["encode_ms"]:.2f} ms; '
          f'realtime {r["realtime"]["fps"]:.0f} of {r["realtime"]["target_fps"]:.0f} fps')
goal = next(r for r in d["results"] if r["size"] == "1920x1080")["pipelined"]["fps"]
print(f'1080p goal 240 fps: {"met" if goal >= 240 else "not met"} ({goal:.0f})')
EOF
