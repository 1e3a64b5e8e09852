#!/bin/bash
# The viewer in a real browser: headless Chromium (Debian's package) driven through the page by
# scripts/browser-test.py, over the DevTools protocol (Python's websocket-client). Installs
# what is missing (Chromium needs root for apt-get; without it the test is skipped, saying so).
# The screenshot is kept in target/browser-test/viewer.png.
#
#   scripts/browser-test.sh [path/to/rest-embree] [screenshot.png]
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
exe=$(realpath "${1:-$root/target/release/rest-embree}")
shot=${2:-$root/target/browser-test/viewer.png}
[ -x "$exe" ] || { echo "browser-test: no binary at $exe (cargo build --release)" >&2; exit 1; }
chromium=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$chromium" ]; then
    if [ "$(id -u)" != 0 ]; then
        echo "browser-test: SKIPPED: Chromium is not installed, and installing it needs root" >&2
        exit 0
    fi
    echo "browser-test: installing chromium" >&2
    DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 install -y -q chromium >/dev/null
    chromium=$(command -v chromium)
fi
cache=${REST_EMBREE_CACHE:-$HOME/.cache/rest-embree}
site=$cache/websocket-client
if ! PYTHONPATH=$site python3 -c 'import websocket' 2>/dev/null; then
    echo "browser-test: installing websocket-client into $site" >&2
    python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore --target "$site" 'websocket-client>=1,<2'
fi
PYTHONPATH=$site python3 "$root/scripts/browser-test.py" "$exe" "$chromium" "$shot"
