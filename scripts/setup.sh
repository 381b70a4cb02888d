#!/usr/bin/env bash
# One-step set-up on a fresh Debian 12 machine: installs the Debian packages liveset needs (only
# those missing, so it is idempotent and fast on re-runs) and builds everything into ./build.
# `--peers` also installs the optional peer libraries (VTK) and builds the peer benchmarks
# (bench/peers: ITK's threshold level set, VTK's Flying Edges) into ./build-peer; neither the tests
# nor CI need them.
set -euo pipefail
cd "$(dirname "$0")/.."
peers=0
for arg in "$@"; do
  case "$arg" in
    --peers) peers=1 ;;
    *) echo "setup: unknown option $arg (use --peers)" >&2; exit 2 ;;
  esac
done

packages=(
  cmake g++ ninja-build pkg-config            # toolchain
  libtbb-dev                                  # oneTBB: parallel level-set update and meshing
  libgtest-dev libgmock-dev libbenchmark-dev  # tests and benchmarks
  libcli11-dev libfmt-dev nlohmann-json3-dev  # command line, formatting, JSON reports
  gnuplot-nox                                 # plots of the Figure 3 experiment
  minc-tools                                  # tests: MINC geometry checked with nii2mnc, mincinfo, worldtovoxel
  libinsighttoolkit5-dev zlib1g-dev           # image IO (NIfTI, MetaImage, NRRD, MINC, DICOM); N4 bias correction
  python3-nibabel python3-numpy               # scripts/brainweb_bias_variant.py; the Python module (python/)
  python3-dev pybind11-dev python3-pytest     # the Python module `liveset` and its pytest suite (ctest runs it)
  python3-distributed python3-dask openssl    # liveset batch: cohorts on Dask distributed (openssl: its TLS test)
  libglfw3-dev libepoxy-dev libimgui-dev      # viewer: window, OpenGL 3.3 loader, Dear ImGui
  libglm-dev libstb-dev                       # viewer: matrices, PNG screenshots
  libegl-dev libgl-dev libgl1-mesa-dri        # OpenGL / EGL (Mesa llvmpipe without a GPU; headless runs)
  xvfb xauth xdotool                          # the real-window smoke test (Xvfb + real input events)
)
if ((peers)); then
  packages+=(libvtk9-dev)                     # peer benchmark: vtkFlyingEdges3D / vtkMarchingCubes (optional)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIVESET_WERROR=ON -DLIVESET_BUILD_PYTHON=ON >/dev/null
cmake --build build -j "$jobs"
if ((peers)); then
  cmake -S . -B build-peer -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIVESET_BUILD_PEER_BENCHMARKS=ON -DLIVESET_BUILD_TESTS=OFF >/dev/null
  cmake --build build-peer -j "$jobs" --target itk_threshold_levelset itk_box_flow vtk_flying_edges
fi
