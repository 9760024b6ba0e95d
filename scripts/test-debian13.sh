#!/usr/bin/env bash
# Runs the test suite against DOLFINx 0.9 (Debian 13) in a debootstrap chroot.
# Needs root.  The chroot is made once (a few minutes) and reused:
#   RAWEHELIX_CHROOT=/var/tmp/rawehelix-trixie (default)
# The working tree is copied in fresh every run (tracked and untracked files,
# not the venv).  Not part of CI.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=${RAWEHELIX_CHROOT:-/var/tmp/rawehelix-trixie}
MARKS=${MARKS:-not long}  # the tests make test selects (make test-debian13 MARKS=long: the long ones)
[ "$(id -u)" -eq 0 ] || { echo "test-debian13: needs root (chroot)" >&2; exit 2; }

if [ ! -x "$ROOT/usr/bin/apt-get" ]; then
  command -v debootstrap >/dev/null || { apt-get update -q; apt-get install -y -q debootstrap; }
  echo "test-debian13: debootstrap trixie into $ROOT"
  debootstrap --variant=minbase trixie "$ROOT" http://deb.debian.org/debian
fi
mounted=()
cleanup() { for m in "${mounted[@]}"; do umount -l "$m" || true; done; }
trap cleanup EXIT
for m in proc sys dev/shm; do
  mkdir -p "$ROOT/$m"
  if ! mountpoint -q "$ROOT/$m"; then
    case "$m" in
      proc) mount -t proc proc "$ROOT/proc" ;;
      sys) mount -t sysfs sysfs "$ROOT/sys" ;;
      *) mount -t tmpfs tmpfs "$ROOT/$m" ;;
    esac
    mounted+=("$ROOT/$m")
  fi
done
cp /etc/resolv.conf "$ROOT/etc/resolv.conf" 2>/dev/null || true
# pip in the chroot trusts what the host trusts (a host behind a proxy with its own CA)
HOST_CA=${SSL_CERT_FILE:-/etc/ssl/certs/ca-certificates.crt}
[ -f "$HOST_CA" ] && cp "$HOST_CA" "$ROOT/etc/rawehelix-host-ca.crt"

PKGS="python3-dolfinx python3-slepc4py python3-petsc4py python3-scipy python3-pytest
python3-meshio python3-gmsh python3-matplotlib python3-h5py python3-tqdm openmpi-bin
python3-pandas python3-multiprocess python3-pip python3-hypothesis python3-sphinx
python3-myst-parser furo"
stamp="$ROOT/var/lib/rawehelix-packages"
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$PKGS" ]; then
  chroot "$ROOT" /usr/bin/env DEBIAN_FRONTEND=noninteractive bash -c \
    "apt-get update -q && apt-get install -y -q --no-install-recommends $(echo $PKGS)"
  # SALib (rawehelix study's Sobol' indices) is not packaged by Debian; its
  # dependencies are, so pip adds SALib alone
  # (Debian 13's pip verifies by OpenSSL's store, truststore: SSL_CERT_FILE, not --cert)
  cert=(); [ -f "$ROOT/etc/rawehelix-host-ca.crt" ] && cert=(SSL_CERT_FILE=/etc/rawehelix-host-ca.crt)
  chroot "$ROOT" env "${cert[@]}" pip install -q --break-system-packages --no-deps "SALib==1.5.1"
  echo "$PKGS" > "$stamp"
fi
# import-linter (the import contracts, tests/test_architecture.py): pip, with its deps
if ! chroot "$ROOT" python3 -c "import importlinter, grimp" 2>/dev/null; then
  cert=(); [ -f "$ROOT/etc/rawehelix-host-ca.crt" ] && cert=(SSL_CERT_FILE=/etc/rawehelix-host-ca.crt)
  chroot "$ROOT" env "${cert[@]}" pip install -q --break-system-packages "import-linter==2.1"
fi

# The package is this folder mapped to the name rawehelix (as pyproject does).
rm -rf "$ROOT/src" && mkdir -p "$ROOT/src/pkgs"
git ls-files -co --exclude-standard -z | tar --null -T - -cf - | tar -xf - -C "$ROOT/src" --one-top-level=rawehelix
ln -s /src/rawehelix "$ROOT/src/pkgs/rawehelix"
chroot "$ROOT" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root \
  PYTHONPATH=/src/pkgs OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
  bash -c "cd /src/rawehelix && python3 -c 'import dolfinx; print(\"DOLFINx\", dolfinx.__version__)' \
    && python3 -m pytest -q -m '$MARKS' -p no:cacheprovider $* \
    && { mpirun -n 2 --oversubscribe python3 -m pytest -q -m 'mpi and ($MARKS)' -p no:cacheprovider $*; rc=\$?; \
         [ \$rc -eq 0 ] || [ \$rc -eq 5 ]; }"  # 5: no test selected
