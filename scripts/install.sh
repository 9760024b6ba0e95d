#!/usr/bin/env bash
# Installs what rawehelix needs on Debian (12 or 13), idempotently:
# Debian's FEniCSx (dolfinx, petsc4py, slepc4py), gmsh, meshio, OpenMPI,
# then a venv with --system-site-packages and `pip install -e .` with numpy
# pinned to the system's version.  A second run takes seconds.
set -euo pipefail
cd "$(dirname "$0")/.."

PKGS="python3-dolfinx python3-petsc4py python3-slepc4py python3-scipy python3-pytest
python3-venv python3-gmsh python3-meshio python3-h5py python3-matplotlib python3-tqdm
python3-hypothesis python3-sphinx python3-myst-parser furo
openmpi-bin make"
missing=$(dpkg-query -W -f='${Package} ${Status}\n' $PKGS 2>/dev/null \
          | awk '$NF != "installed" {print $1}'; \
          for p in $PKGS; do dpkg-query -W "$p" >/dev/null 2>&1 || echo "$p"; done)
missing=$(echo $missing | tr ' ' '\n' | sort -u | tr '\n' ' ')
if [ -n "${missing// /}" ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "install: apt-get install $missing"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends $missing
fi

PY=/usr/bin/python3
VENV=.venv
if [ ! -x "$VENV/bin/python" ]; then
  echo "install: venv $VENV (system site packages)"
  $PY -m venv --system-site-packages "$VENV"
fi
stamp="$VENV/.rawehelix-installed"
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ] || [ scripts/install.sh -nt "$stamp" ]; then
  numpy_version=$($PY -c 'import numpy; print(numpy.__version__)')
  echo "install: pip install -e . (numpy==$numpy_version)"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -e . "numpy==$numpy_version" \
      "import-linter==2.1"  # lint-imports: the import contracts of .importlinter (tests/test_architecture.py)
  # pyconturb (operation/turbulence.py, the turbulent wind): --no-deps, because pip
  # does not see Debian's h5py (dist-info h5py._debian_h5py_serial) and would install
  # PyPI's over it; numpy, scipy, pandas and h5py are already there
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-deps "pyconturb==2.7.4"
  # numba: the compiled time steps (-rawehelix_ts_compiled 1, solvers/compiled_step.py);
  # 0.57.1: the version measured here with Debian 12's numpy 1.24.2 and Python 3.11
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check "numpy==$numpy_version" \
      "numba==0.57.1"
  # pyvista renders off screen; it is optional and must not move numpy.  Before 0.46:
  # later ones bring cyclopts -> rich -> markdown-it-py >= 2.2, which shadows Debian's
  # 2.1 and breaks Debian's myst-parser (make docs), with a resolver error at install.
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check "numpy==$numpy_version" \
      "pyvista<0.46" imageio || echo "install: pyvista unavailable; 3D pictures are skipped"
  touch "$stamp"
fi
"$VENV/bin/python" -c 'import dolfinx, petsc4py, slepc4py, rawehelix' \
  || { echo "install: the venv cannot import dolfinx/rawehelix" >&2; exit 1; }
