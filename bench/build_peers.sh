#!/usr/bin/env bash
# The peers of bench/peers.py, in $1 (build/peers):
# - ESIM's Python simulator (esim_py, from uzh-rpg/rpg_vid2e) into $1/esim_py. Sources: $PEERS_SRC
#   (a checkout of rpg_vid2e) if set, else a clone from GitHub. Needs Debian's libopencv-dev,
#   libeigen3-dev, libboost-filesystem-dev and cmake; pybind11 comes from PyPI.
# - v2e's emulator (SensorsINI/v2e, its v2ecore package) into $1/src/v2e, with its own environment
#   $1/v2e-venv on Debian's Python and Debian's CPU-only torch (python3-torch 1.13): PyPI's Linux
#   torch is the CUDA build, several GB of NVIDIA libraries this benchmark never uses. Sources:
#   $V2E_SRC (a checkout) if set, else a clone from GitHub.
set -euo pipefail
out="$1"
python="$2"
build_v2e() {
  [ -f "$out/v2e-venv/done" ] && return 0
  mkdir -p "$out/src"
  if [ -n "${V2E_SRC:-}" ]; then
    rm -rf "$out/src/v2e" && mkdir -p "$out/src/v2e" && cp -r "$V2E_SRC/v2ecore" "$out/src/v2e/"
  elif [ ! -d "$out/src/v2e/v2ecore" ]; then
    git clone --depth 1 https://github.com/SensorsINI/v2e "$out/src/v2e" 2>/dev/null \
      || { echo "evclust: cannot clone github.com/SensorsINI/v2e; set V2E_SRC to a checkout of it" >&2; exit 2; }
  fi
  local debian="python3-torch python3-opencv python3-h5py python3-numba python3-tk python3-scipy python3-tqdm"
  for pkg in $debian; do
    dpkg -s "$pkg" >/dev/null 2>&1 || { echo "evclust: bench-peers needs Debian's $pkg for v2e: apt-get install $debian" >&2; exit 2; }
  done
  /usr/bin/python3 -m venv --system-site-packages "$out/v2e-venv"
  # --no-deps: what these need is Debian's already; pip would otherwise pull a numpy that torch 1.13 was not built for.
  "$out/v2e-venv/bin/pip" install --quiet --no-deps screeninfo engineering-notation easygui dv-processing
  "$out/v2e-venv/bin/python" -c "import torch; assert not torch.cuda.is_available()" \
    || { echo "evclust: the v2e environment's torch does not import" >&2; exit 2; }
  touch "$out/v2e-venv/done"
}
build_v2e
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
cmake="$(dirname "$python")/cmake"  # the one just installed, whatever is first on PATH
build="$src/esim_py/build"
mkdir -p "$build"
# esim_py asks for CMake 3.3; PyPI's CMake 4 refuses anything older than 3.5 without this policy floor.
"$cmake" -S "$src/esim_py" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_POLICY_VERSION_MINIMUM=3.5 -DPYTHON_EXECUTABLE="$python" \
  -Dpybind11_DIR="$("$python" -c 'import pybind11; print(pybind11.get_cmake_dir())')" > "$build/cmake.log" 2>&1 \
  || { tail -n 20 "$build/cmake.log" >&2; echo "evclust: configuring esim_py failed (log: $build/cmake.log)" >&2; exit 2; }
"$cmake" --build "$build" -j 2 > "$build/make.log" 2>&1 \
  || { tail -n 20 "$build/make.log" >&2; echo "evclust: building esim_py failed (log: $build/make.log)" >&2; exit 2; }
mkdir -p "$out/esim_py"
cp "$build"/esim_py*.so "$out/esim_py/"
touch "$out/esim_py/done"
