#!/usr/bin/env bash
# Build the continuation peer (AUTO-07p) and the sweep peer (SciPy) for R2, N = 2
# (r2n2.exe) and any N (rn.exe)
# (idempotent).
#
#   bench/auto/build.sh [OUT_DIR] [--no-python]
#
# OUT_DIR defaults to bench/auto/build/ (git-ignored). Produces
#   OUT_DIR/r2n2.exe   AUTO-07p executable: r2n2.f90 compiled with gfortran and
#                      linked with the AUTO-07p 0.9.2 library objects of the
#                      Debian package auto-07p (/usr/lib/auto-07p/lib/*.o)
#   OUT_DIR/rn.exe     the same from rn.f90 (any N, NDIM = 2N + 2)
#   OUT_DIR/venv/      Python venv with requirements.txt (numpy, scipy) for
#                      sweep_scipy.py and check_auto.py
# Installs auto-07p and gfortran with apt-get if missing (needs root or sudo and
# the Debian mirror), and the pinned numpy/scipy from PyPI into the venv if
# missing. Exits non-zero with a "build.sh: ERROR:" message on any failure.
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
OUT="$HERE/build"
WITH_PYTHON=1
for arg in "$@"; do
  case "$arg" in
    --no-python) WITH_PYTHON=0 ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) OUT="$arg" ;;
  esac
done

die() { echo "build.sh: ERROR: $*" >&2; exit 1; }

mkdir -p "$OUT" || die "cannot create output directory $OUT"
OUT="$(cd "$OUT" && pwd)"
AUTO_LIB=/usr/lib/auto-07p/lib

# ---- 1. AUTO-07p and gfortran --------------------------------------------
PKGS=""
[ -f "$AUTO_LIB/main.o" ] || PKGS="$PKGS auto-07p"
command -v gfortran >/dev/null || PKGS="$PKGS gfortran"
if [ -n "$PKGS" ]; then
  echo "build.sh: installing$PKGS" >&2
  command -v apt-get >/dev/null || die "apt-get not found; install auto-07p and gfortran by hand"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || die "need root (or sudo) to apt-get install$PKGS"
    SUDO="sudo"
  fi
  export DEBIAN_FRONTEND=noninteractive
  # shellcheck disable=SC2086
  if ! $SUDO apt-get install -y --no-install-recommends $PKGS; then
    $SUDO apt-get update || die "apt-get update failed"
    # shellcheck disable=SC2086
    $SUDO apt-get install -y --no-install-recommends $PKGS || die "apt-get install$PKGS failed"
  fi
fi
[ -f "$AUTO_LIB/main.o" ] || die "AUTO-07p library objects missing in $AUTO_LIB after install"
command -v gfortran >/dev/null || die "gfortran missing after install"
VERSION="$(dpkg-query -W -f='${Version}' auto-07p 2>/dev/null || echo unknown)"
case "$VERSION" in
  0.9.2*) ;;
  *) echo "build.sh: WARNING: expected auto-07p 0.9.2, found: $VERSION" >&2 ;;
esac

# ---- 2. compile and link (the flags of /usr/lib/auto-07p/cmds/cmds.make) ---
FFLAGS="-O2 -fPIC -std=legacy -fopenmp"
build_exe() {  # build_exe NAME: NAME.f90 -> OUT/NAME.exe (if out of date)
  local name="$1"
  if [ ! -x "$OUT/$name.exe" ] || [ "$HERE/$name.f90" -nt "$OUT/$name.exe" ] || [ "$0" -nt "$OUT/$name.exe" ]; then
    # shellcheck disable=SC2086
    gfortran $FFLAGS -c "$HERE/$name.f90" -o "$OUT/$name.o" || die "compiling $name.f90 failed"
    # shellcheck disable=SC2086
    gfortran $FFLAGS "$OUT/$name.o" -o "$OUT/$name.exe.tmp" "$AUTO_LIB"/*.o || die "linking $name.exe failed"
    mv -f "$OUT/$name.exe.tmp" "$OUT/$name.exe"
  fi
}
build_exe r2n2   # N = 2
build_exe rn     # any N, from NDIM = 2N + 2
# smoke run: the amplitude homotopy (run 1 of run_auto.py), a fraction of a second
SMOKE="$OUT/smoke"
mkdir -p "$SMOKE"
cat > "$SMOKE/c.smoke" <<'CEOF'
e = 'r2n2'
sv = 'smoke'
NDIM = 6
IPS = 2
IRS = 0
ILP = 1
ICP = [2, 11]
NTST = 100
NCOL = 4
IAD = 3
ISP = 2
ISW = 1
NMX = 200
NPR = 1000
JAC = 1
EPSL = 1e-07
EPSU = 1e-07
EPSS = 1e-05
DS = 0.01
DSMIN = 1e-07
DSMAX = 0.1
UZSTOP = {2: 0.5}
CEOF
for exe in r2n2 rn; do
  sed "s/^e = .*/e = '$exe'/" "$SMOKE/c.smoke" > "$SMOKE/c.smoke.$exe"
  ( cd "$SMOKE" && OMP_NUM_THREADS=1 "$OUT/$exe.exe" < "c.smoke.$exe" > "smoke.$exe.log" 2>&1 ) \
    || die "smoke run of $exe.exe failed (see $SMOKE/smoke.$exe.log)"
  grep -q " UZ " "$SMOKE/smoke.$exe.log" || die "smoke run of $exe.exe did not reach its user point (see $SMOKE/smoke.$exe.log)"
done
echo "build.sh: built $OUT/r2n2.exe and $OUT/rn.exe (auto-07p $VERSION, $(gfortran --version | head -1))"

# ---- 3. Python venv for sweep_scipy.py / check_auto.py --------------------
if [ "$WITH_PYTHON" -eq 1 ]; then
  PY="${PYTHON:-python3}"
  command -v "$PY" >/dev/null || die "$PY not found"
  if [ ! -x "$OUT/venv/bin/python" ]; then
    "$PY" -m venv "$OUT/venv" || die "python -m venv failed (Debian: apt-get install python3-venv)"
  fi
  if ! "$OUT/venv/bin/python" - "$HERE/requirements.txt" <<'PYEOF'
import sys
from importlib.metadata import version, PackageNotFoundError
want = dict(l.strip().split("==") for l in open(sys.argv[1]) if "==" in l)
try:
    sys.exit(0 if all(version(k) == v for k, v in want.items()) else 1)
except PackageNotFoundError:
    sys.exit(1)
PYEOF
  then
    "$OUT/venv/bin/python" -m pip install --quiet -r "$HERE/requirements.txt" \
      || die "pip install -r requirements.txt failed"
  fi
  "$OUT/venv/bin/python" "$HERE/sweep_scipy.py" --only 0.9 --p1 1 --p2 2 --quiet --out /dev/null >/dev/null \
    || die "smoke run of sweep_scipy.py failed"
  echo "build.sh: Python peer ready: $OUT/venv/bin/python $HERE/sweep_scipy.py"
fi
