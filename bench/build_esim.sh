#!/usr/bin/env bash
# Build ESIM's Python simulator (esim_py, from uzh-rpg/rpg_vid2e) into $1/esim_py for bench/peers.py.
# Sources: $PEERS_SRC (a checkout of rpg_vid2e) if set, else a clone from GitHub. Needs Debian's
# libopencv-dev, libeigen3-dev, libboost-filesystem-dev and cmake; pybind11 comes from PyPI.
set -euo pipefail
out="$1"
python="$2"
if [ -f "$out/esim_py/done" ]; then exit 0; fi
for pkg in libopencv-dev libeigen3-dev libboost-filesystem-dev; do
  dpkg -s "$pkg" >/dev/null 2>&1 || { echo "evclust: bench-peers needs $pkg: apt-get install libopencv-dev libeigen3-dev libboost-filesystem-dev libboost-system-dev" >&2; exit 2; }
done
src="$out/src"
mkdir -p "$src"
if [ -n "${PEERS_SRC:-}" ]; then
  rm -rf "$src/esim_py" && cp -r "$PEERS_SRC/esim_py" "$src/esim_py"
elif [ ! -d "$src/esim_py" ]; then
  git clone --depth 1 https://github.com/uzh-rpg/rpg_vid2e "$src/rpg_vid2e" 2>/dev/null \
    || { echo "evclust: cannot clone github.com/uzh-rpg/rpg_vid2e; set PEERS_SRC to a checkout of it" >&2; exit 2; }
  mv "$src/rpg_vid2e/esim_py" "$src/esim_py" && rm -rf "$src/rpg_vid2e"
fi
"$python" -m pip install --quiet pybind11 cmake
build="$src/esim_py/build"
mkdir -p "$build"
cmake -S "$src/esim_py" -B "$build" -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE="$python" \
  -Dpybind11_DIR="$("$python" -c 'import pybind11; print(pybind11.get_cmake_dir())')" > "$build/cmake.log"
cmake --build "$build" -j 2 > "$build/make.log"
mkdir -p "$out/esim_py"
cp "$build"/esim_py*.so "$out/esim_py/"
touch "$out/esim_py/done"
