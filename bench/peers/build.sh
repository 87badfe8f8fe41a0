#!/usr/bin/env bash
# Build the R2 peer programs (idempotent).
#
#   bench/peers/build.sh [OUT_DIR] [--no-python]
#
# OUT_DIR defaults to bench/peers/build/ (git-ignored). Produces
#   OUT_DIR/r2_sundials      C peer (SUNDIALS 6.4.1 from Debian libsundials-dev)
#   OUT_DIR/venv/            Python venv with requirements.txt (SciPy peer),
#                            run as OUT_DIR/venv/bin/python bench/peers/r2_scipy.py
# Installs libsundials-dev with apt-get if its headers are missing (needs root
# and access to the Debian mirror), and the pinned numpy/scipy from PyPI into the
# venv if they are missing. Exits non-zero with a message on any failure.
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
OUT="$HERE/build"
WITH_PYTHON=1
for arg in "$@"; do
  case "$arg" in
    --no-python) WITH_PYTHON=0 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) OUT="$arg" ;;
  esac
done

die() { echo "build.sh: ERROR: $*" >&2; exit 1; }

mkdir -p "$OUT" || die "cannot create output directory $OUT"
OUT="$(cd "$OUT" && pwd)"

# ---- 1. SUNDIALS ----------------------------------------------------------
if [ ! -f /usr/include/arkode/arkode_erkstep.h ] || [ ! -f /usr/include/cvode/cvode.h ]; then
  echo "build.sh: SUNDIALS headers missing; installing libsundials-dev" >&2
  command -v apt-get >/dev/null || die "apt-get not found; install SUNDIALS 6.4.x development files by hand"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || die "need root (or sudo) to apt-get install libsundials-dev"
    SUDO="sudo"
  fi
  export DEBIAN_FRONTEND=noninteractive
  if ! $SUDO apt-get install -y --no-install-recommends libsundials-dev; then
    $SUDO apt-get update || die "apt-get update failed"
    $SUDO apt-get install -y --no-install-recommends libsundials-dev \
      || die "apt-get install libsundials-dev failed"
  fi
fi
[ -f /usr/include/arkode/arkode_erkstep.h ] || die "SUNDIALS headers still missing after install"

VERSION_LINE="$(grep -h 'define SUNDIALS_VERSION ' /usr/include/sundials/sundials_config.h || true)"
case "$VERSION_LINE" in
  *'"6.4.'*) ;;
  *) echo "build.sh: WARNING: expected SUNDIALS 6.4.x, found: $VERSION_LINE" >&2 ;;
esac

command -v gcc >/dev/null || die "gcc not found (apt-get install gcc)"

# ---- 2. compile -----------------------------------------------------------
LIBS="-lsundials_arkode -lsundials_cvode -lsundials_nvecserial -lsundials_sunmatrixband \
-lsundials_sunlinsolband -lsundials_sunnonlinsolfixedpoint -lm"
# shellcheck disable=SC2086
gcc -O2 -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -Wall -Wextra \
  -o "$OUT/r2_sundials.tmp" "$HERE/r2_sundials.c" $LIBS \
  || die "compiling r2_sundials.c failed"
mv -f "$OUT/r2_sundials.tmp" "$OUT/r2_sundials"
"$OUT/r2_sundials" arkode-dp5 2 0.95 1 1e-6 1e-9 1 >/dev/null \
  || die "smoke run of $OUT/r2_sundials failed"
echo "build.sh: built $OUT/r2_sundials ($VERSION_LINE)"

# ---- 3. Python venv for the SciPy peer ------------------------------------
if [ "$WITH_PYTHON" -eq 1 ]; then
  PY="${PYTHON:-python3}"
  command -v "$PY" >/dev/null || die "$PY not found"
  if [ ! -x "$OUT/venv/bin/python" ]; then
    "$PY" -m venv "$OUT/venv" || die "python -m venv failed (Debian: apt-get install python3-venv)"
  fi
  if ! "$OUT/venv/bin/python" - "$HERE/requirements.txt" <<'EOF'
import sys
from importlib.metadata import version, PackageNotFoundError
want = dict(l.strip().split("==") for l in open(sys.argv[1]) if "==" in l)
try:
    sys.exit(0 if all(version(k) == v for k, v in want.items()) else 1)
except PackageNotFoundError:
    sys.exit(1)
EOF
  then
    "$OUT/venv/bin/python" -m pip install --quiet -r "$HERE/requirements.txt" \
      || die "pip install -r requirements.txt failed"
  fi
  "$OUT/venv/bin/python" "$HERE/r2_scipy.py" dop853 2 0.95 1 1e-6 1e-9 1 >/dev/null \
    || die "smoke run of r2_scipy.py failed"
  echo "build.sh: Python peer ready: $OUT/venv/bin/python $HERE/r2_scipy.py"
fi
