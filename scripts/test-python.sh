#!/usr/bin/env bash
# The cocotb extension (python/cocotbext-sja1000) end to end: builds its
# wheel with maturin, installs it into two virtualenvs and runs the cocotb
# bench of rtl/can_top (examples/test_can_top.py) and its one-line mutant:
#   Icarus    with cocotb 2.x  (cocotb 2.x needs Verilator >= 5.036)
#   Verilator with cocotb 1.9.2 (the newest cocotb that takes Debian's 5.006)
# Each pair must pass on rtl/ and fail on the mutant with the diagnosis.
# A pair whose simulator or packages cannot be had is skipped with the
# reason; exit status 1 on any wrong outcome.
#
#   scripts/test-python.sh            # both pairs
#   scripts/test-python.sh --bench    # also the bench without the scoreboard (ratio)
# Virtualenvs are kept in target/pyenv-* (PYENV_DIR to move them).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
envs="${PYENV_DIR:-$root/target}"
bench=0
[ "${1:-}" = "--bench" ] && bench=1
fail=0
skipped=()

skip() { echo "test-python: SKIPPED $1" >&2; skipped+=("$1"); }

# venv NAME PACKAGES...: a virtualenv with these packages, or nothing (skip).
venv() {
  local dir="$envs/pyenv-$1"; shift
  if [ ! -x "$dir/bin/python" ]; then
    python3 -m venv "$dir" || return 1
  fi
  "$dir/bin/pip" install -q --disable-pip-version-check "$@" || return 1
  echo "$dir"
}

if ! command -v python3 >/dev/null; then
  skip "everything: no python3"; exit 0
fi

echo "== cocotbext-sja1000: build the wheel =="
if ! tools=$(venv build maturin); then
  skip "everything: maturin cannot be installed from PyPI"; exit 0
fi
wheels="$root/target/wheels"
rm -f "$wheels"/cocotbext_sja1000-*.whl
( cd python/cocotbext-sja1000 && CARGO_TARGET_DIR="$root/target" "$tools/bin/maturin" build --release -q -i "$tools/bin/python" )
wheel=$(ls "$wheels"/cocotbext_sja1000-*.whl)

# run_pair SIM COCOTB_SPEC NAME
run_pair() {
  local sim=$1 spec=$2 name=$3 py
  if ! command -v "$( [ "$sim" = icarus ] && echo iverilog || echo verilator)" >/dev/null; then
    skip "$name: $sim is not installed"; return
  fi
  if ! py=$(venv "$name" "$spec" python-can); then
    skip "$name: $spec or python-can cannot be installed from PyPI"; return
  fi
  "$py/bin/pip" install -q --disable-pip-version-check --force-reinstall --no-deps "$wheel"
  local ex=python/cocotbext-sja1000/examples work
  work=$(mktemp -d "${TMPDIR:-/tmp}/cocotb-can.XXXXXX")
  echo "== $name: rtl/ (must pass) =="
  if "$py/bin/python" "$ex/run.py" --sim "$sim" --build-dir "$work/rtl" > "$work/rtl.log" 2>&1; then
    grep -E "TESTS=|run time" "$work/rtl.log"
  else
    cat "$work/rtl.log"; echo "test-python: $name FAILED on rtl/" >&2; fail=1
  fi
  echo "== $name: one-line mutant of rtl/ (must fail with the diagnosis) =="
  if "$py/bin/python" "$ex/run.py" --sim "$sim" --mutant --build-dir "$work/mutant" > "$work/mutant.log" 2>&1; then
    sed -n '/^mutant caught/,/^Figures/p' "$work/mutant.log"
  else
    cat "$work/mutant.log"; echo "test-python: $name: the mutant was not diagnosed" >&2; fail=1
  fi
  if [ "$bench" = 1 ]; then
    echo "== $name: without the scoreboard =="
    "$py/bin/python" "$ex/run.py" --sim "$sim" --no-scoreboard --build-dir "$work/nosb" > "$work/nosb.log" 2>&1 || { cat "$work/nosb.log"; fail=1; }
    grep -E "TESTS=|run time" "$work/nosb.log"
    local with without
    with=$(sed -n 's/^run time \([0-9.]*\) s.*/\1/p' "$work/rtl.log")
    without=$(sed -n 's/^run time \([0-9.]*\) s.*/\1/p' "$work/nosb.log")
    awk -v a="$with" -v b="$without" -v n="$name" 'BEGIN { if (b > 0) printf "bench %s: with the scoreboard %.2f s, without %.2f s, ratio %.2f (one run)\n", n, a, b, a / b }'
  fi
  rm -rf "$work"
}

run_pair icarus "cocotb>=2,<3" cocotb2-icarus
run_pair verilator "cocotb==1.9.2" cocotb19-verilator

if [ ${#skipped[@]} -gt 0 ]; then
  printf 'test-python: skipped: %s\n' "${skipped[@]}"
fi
exit $fail
