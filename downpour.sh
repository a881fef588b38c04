#!/usr/bin/env bash
# Downpour quick start on Debian 12:
#   ./downpour.sh demo    install what is missing, build, start the server, a demo drive and the viewer
#   ./downpour.sh test    install what is missing, build, run every test (ctest)
#   ./downpour.sh build   install what is missing, build (Release, into build/)
#   ./downpour.sh server  build, then run the server alone (arguments after "server" go to it)
#   ./downpour.sh bench   build, then run the benchmarks (JSON on stdout)
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)
BUILD=${DOWNPOUR_BUILD_DIR:-$ROOT/build}
PY=/usr/bin/python3  # Debian's interpreter, with python3-grpcio

PACKAGES=(cmake ninja-build g++ pkg-config
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libturbojpeg0-dev libspdlog-dev libglm-dev libcli11-dev nlohmann-json3-dev libpng-dev
  libegl-dev libgl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-grpcio python3-protobuf python3-pil)

install_packages() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  ((${#missing[@]})) || return 0
  echo "Installing: ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

build() {
  install_packages
  cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$BUILD" -j "$(nproc)"
}

# Software GL: one rasterizer thread per core unless the caller chose.
export LP_NUM_THREADS=${LP_NUM_THREADS:-$(nproc)}

demo() {
  build
  local dir="$BUILD/demo"
  mkdir -p "$dir"
  rm -f "$dir/port"
  local pids=()
  cleanup() {
    trap - INT TERM EXIT
    for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
    wait 2>/dev/null || true
  }
  trap cleanup INT TERM EXIT
  "$BUILD/downpour-server" --listen "${DOWNPOUR_LISTEN:-127.0.0.1:50051}" --port-file "$dir/port" \
    >"$dir/server.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 1 600); do [ -s "$dir/port" ] && break; sleep 0.1; done
  [ -s "$dir/port" ] || { echo "the server did not start; see $dir/server.log"; cat "$dir/server.log"; exit 1; }
  local target="127.0.0.1:$(cat "$dir/port")"
  PYTHONPATH="$ROOT/clients/python" DOWNPOUR_PYTHON_STUBS="$BUILD/python" \
    "$PY" -m downpour_client play "$ROOT/clients/scenarios/highway_heavy_rain.json" \
    --server "$target" --mode realtime >"$dir/drive.log" 2>&1 &
  pids+=($!)
  PYTHONPATH="$ROOT/clients/python" DOWNPOUR_PYTHON_STUBS="$BUILD/python" \
    "$PY" "$ROOT/clients/viewer/viewer.py" --server "$target" --port "${DOWNPOUR_VIEWER_PORT:-8080}" \
    >"$dir/viewer.log" 2>&1 &
  pids+=($!)
  echo
  echo "Downpour demo running: server on $target ($(grep -o 'renderer: .*' "$dir/server.log" || true))"
  echo "  drive:  highway_heavy_rain, realtime (log: $dir/drive.log)"
  echo "  viewer: http://127.0.0.1:${DOWNPOUR_VIEWER_PORT:-8080}/   (Ctrl-C stops everything)"
  wait -n "${pids[@]}" || true
  echo "a demo process ended; see the logs in $dir"
}

case "${1:-}" in
  demo) demo ;;
  test)
    build
    ctest --test-dir "$BUILD" --output-on-failure --timeout 900
    ;;
  build) build ;;
  server)
    shift
    build
    exec "$BUILD/downpour-server" "$@"
    ;;
  bench)
    build
    "$BUILD/downpour-bench" "${@:2}"
    ;;
  *)
    sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
