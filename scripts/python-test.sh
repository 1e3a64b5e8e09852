#!/usr/bin/env bash
# The Python package's tests (python/tests, pytest): built into target/pyenv with pytest and
# what the example notebook needs (examples/relativity.ipynb, run by the tests with nbclient),
# then run against the binary in target/release (the command line they compare with).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
VENV=$root/target/pyenv "$root/scripts/python-install.sh" pytest nbclient nbformat ipykernel matplotlib
cd "$root"
REST_EMBREE=${1:-$root/target/release/rest-embree} target/pyenv/bin/python -m pytest -q -p no:cacheprovider python/tests
