#!/usr/bin/env bash
# Set up a fresh machine: Debian tools the tests use as oracles, then a virtual
# environment with cospherical and its test dependencies in .venv/.
set -euo pipefail
cd "$(dirname "$0")/.."

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
packages=()
command -v qdelaunay >/dev/null 2>&1 || packages+=(qhull-bin)   # Qhull's merged Delaunay regions: the oracle
command -v pdflatex >/dev/null 2>&1 || packages+=(texlive-latex-base texlive-latex-recommended texlive-pictures)  # render --pdf: the LaTeX tables compiled in the tests
command -v pdftoppm >/dev/null 2>&1 || packages+=(poppler-utils)  # PDF page -> PNG in the tests
command -v tetgen >/dev/null 2>&1 || packages+=(tetgen)  # bench_outputs.py and mesh --dual: the tetrahedral mesher beside ours
[ -x /usr/bin/time ] || packages+=(time)  # GNU time: the docs' bench_peers.py example reads a command's peak memory from it
command -v chromium >/dev/null 2>&1 || packages+=(chromium)  # the docs site's pages opened headless in the tests
command -v chromedriver >/dev/null 2>&1 || packages+=(chromium-driver)  # selenium drives that chromium through it
command -v cc >/dev/null 2>&1 || packages+=(gcc)  # the docs' C reader of the pattern-table store, compiled in the tests
command -v g++ >/dev/null 2>&1 || packages+=(g++)  # the same reader compiled as C++
[ -e /usr/include/sqlite3.h ] || packages+=(libsqlite3-dev)  # the C reader's headers: SQLite
[ -e /usr/include/zlib.h ] || packages+=(zlib1g-dev)  # the C reader's headers: zlib
# The gmsh wheel's library links these (ldd libgmsh.so): present on a desktop, not on a bare server
for pair in libGLU.so.1:libglu1-mesa libGL.so.1:libgl1 libXrender.so.1:libxrender1 libXcursor.so.1:libxcursor1 \
    libXfixes.so.3:libxfixes3 libXext.so.6:libxext6 libXft.so.2:libxft2 libfontconfig.so.1:libfontconfig1 \
    libXinerama.so.1:libxinerama1 libX11.so.6:libx11-6 libgomp.so.1:libgomp1; do
  grep -q "${pair%%:*}" < <(ldconfig -p 2>/dev/null) || packages+=("${pair##*:}")
done
python3 -c "import ensurepip, venv" >/dev/null 2>&1 || packages+=(python3-venv)  # stock Ubuntu lacks it
if [ ${#packages[@]} -gt 0 ]; then
  # Wait up to 10 minutes for another apt-get or dpkg (unattended upgrades on a fresh
  # machine) to release the lock, instead of failing at once.
  apt=(apt-get -o DPkg::Lock::Timeout=600)
  $sudo "${apt[@]}" update -qq
  DEBIAN_FRONTEND=noninteractive $sudo "${apt[@]}" install -y -qq "${packages[@]}" >/dev/null
fi

python3 -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e '.[test,docs]'
# Bytecode for our own modules now: an editable install leaves them uncompiled, and where
# PYTHONDONTWRITEBYTECODE is set every command would compile them again (~30 ms a start).
.venv/bin/python -m compileall -q src >/dev/null
