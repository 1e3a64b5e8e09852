#!/usr/bin/env bash
# The code as the house keeps it: formatted, and no lint in the library alone (no Embree, no
# command line: what a program that links it builds), in the whole program, or in the Python
# package.
#
#   scripts/lint.sh           run them, in target/lint (`make lint`)
#   scripts/lint.sh --start   run them in the background, at the lowest priority, output to
#                             target/lint.log (`make test` starts them beside its builds)
#   scripts/lint.sh --wait    wait for the background run, show its output, and exit with its
#                             status
#
# The lints check, they build nothing: their target directory is their own, so they run beside
# `cargo test`'s build (one target directory takes one cargo at a time) on the cores it leaves
# idle (its last test binary is compiled on one core), and finish before the tests do.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
mkdir -p target
log=target/lint.log
status=target/lint.status

# Each step's failure ends it (explicitly: `set -e` does not hold in a function run on the left
# of `||`, as the background run's is).
lint() {
    export CARGO_TARGET_DIR=$root/target/lint
    local cargo=${CARGO:-cargo}
    set -x
    "$cargo" fmt --all --check || return 1
    "$cargo" clippy --release --no-default-features --all-targets -- -D warnings || return 1
    "$cargo" clippy --release --all-targets -- -D warnings || return 1
    "$cargo" clippy --release -p rest-embree-python -- -D warnings || return 1
}

case "${1:-}" in
    --start)
        # A run left by a `make test` that stopped before its end (a failed test, Ctrl-C) is
        # stopped with its cargo: it would write its verdict over this run's.
        old=$(cat target/lint.pid 2>/dev/null || true)
        if [ -n "$old" ] && kill -0 "$old" 2>/dev/null; then
            kill -- -"$old" 2>/dev/null || kill "$old" 2>/dev/null || true
            while kill -0 "$old" 2>/dev/null; do sleep 0.2; done
        fi
        rm -f "$status"
        # In a process group of its own (setsid), so that the line above can stop it whole.
        setsid "$0" --run </dev/null >/dev/null 2>&1 &
        echo $! >target/lint.pid
        echo "the lints: started beside the tests (scripts/lint.sh; their output follows the tests)"
        ;;
    --run)
        # The lowest priority: the build beside them keeps the cores it uses.
        renice -n 19 -p $$ >/dev/null
        code=0
        (lint) >"$log" 2>&1 || code=$?
        echo "$code $$" >"$status"
        ;;
    --wait)
        pid=$(cat target/lint.pid 2>/dev/null || true)
        while [ ! -s "$status" ]; do
            if [ -z "$pid" ] || ! kill -0 "$pid" 2>/dev/null; then
                [ -s "$status" ] && break
                echo "lint: no run under way and none finished (scripts/lint.sh --start)" >&2
                exit 1
            fi
            sleep 1
        done
        sed 's/^/lint: /' "$log"
        read -r code by <"$status"
        if [ "$by" != "$pid" ]; then
            echo "lint: the verdict is another run's ($by, not $pid)" >&2
            exit 1
        fi
        if [ "$code" != 0 ]; then
            echo "make test: FAILED: the lints (above; scripts/lint.sh runs them alone)" >&2
            exit 1
        fi
        echo "the lints: passed"
        ;;
    "")
        lint
        ;;
    *)
        echo "usage: scripts/lint.sh [--start | --wait]" >&2
        exit 2
        ;;
esac
