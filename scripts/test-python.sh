#!/usr/bin/env bash
# The cocotb extension (python/cocotbext-sja1000) end to end: builds its
# wheel with maturin, installs it into two virtualenvs and runs the cocotb
# bench of rtl/can_top (examples/test_can_top.py) and its one-line mutant,
# the bench of rtl/can_avalon (examples/test_can_avalon.py: the scoreboard
# fed by the Avalon-MM monitor) and its mutant, whose divergence marker must
# sit at the failing read, the Avalon-MM master and monitor on three small
# slaves (waitrequest, pipelined reads, fixed wait states: examples/
# avalon_slaves.v), the benches of rtl/can_axi4lite and rtl/can_apb
# (examples/test_can_amba.py: the scoreboard fed by the AXI4-Lite and APB
# monitors, their protocol checks), the benches of rtl/can_regport and
# rtl/can_top_mcu in Motorola mode (examples/test_can_regport_motorola.py:
# the register-port and Motorola monitors) and their mutants, and the
# package README's example as written:
#   Icarus    with cocotb 2.x  (cocotb 2.x needs Verilator >= 5.036)
#   Verilator with cocotb 1.9.2 (the newest cocotb that takes Debian's 5.006)
# Each pair must pass on rtl/ and fail on the mutant with the diagnosis.
# A pair whose simulator or packages cannot be had is skipped with the
# reason; exit status 1 on any wrong outcome.
#
#   scripts/test-python.sh            # everything on both pairs
#   scripts/test-python.sh --quick    # what scripts/test.sh runs: the same, but
#                                     # the can_avalon, can_axi4lite, can_apb,
#                                     # can_regport and can_top_mcu benches,
#                                     # their mutants and the Avalon agents on
#                                     # small slaves under Icarus only (under
#                                     # Verilator: thirteen more builds)
#   scripts/test-python.sh --bench    # also the benchmark: the example without
#                                     # the scoreboard, and one test against
#                                     # `cancosim run` of the same workload
# Exit status: 0 when every pair that could run passed (a pair whose
# simulator or PyPI packages cannot be had is skipped with the reason), 1 on
# any wrong outcome or a wheel that does not build.
# Virtualenvs are kept in target/pyenv-* (PYENV_DIR to move them).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
envs="${PYENV_DIR:-$root/target}"
bench=0
quick=0
case "${1:-}" in
  --bench) bench=1 ;;
  --quick) quick=1 ;;
  "") ;;
  *) echo "usage: scripts/test-python.sh [--quick | --bench]" >&2; exit 2 ;;
esac
fail=0
skipped=()

skip() { echo "test-python: SKIPPED $1" >&2; skipped+=("$1"); }

# venv NAME PACKAGES...: a virtualenv with these packages; on failure,
# nothing, and why in $why.
why=""
venv() {
  local dir="$envs/pyenv-$1" log; shift
  log=$(mktemp)
  if [ ! -x "$dir/bin/pip" ]; then
    if ! python3 -m venv "$dir" > "$log" 2>&1; then
      why="python3 -m venv fails ($(tail -n 1 "$log"); Debian: apt install python3-venv)"
      rm -rf "$dir" "$log"; return 1
    fi
  fi
  # `python -m`: a virtualenv copied to another place keeps scripts whose
  # #! line names the old one.
  if ! "$dir/bin/python" -m pip install -q --disable-pip-version-check "$@" > "$log" 2>&1; then
    why="pip install $* failed: $(grep -m1 -E "^ERROR" "$log" || tail -n 1 "$log")"
    rm -f "$log"; return 1
  fi
  rm -f "$log"
  echo "$dir"
}

if ! command -v python3 >/dev/null; then
  skip "everything: no python3"; exit 0
fi

echo "== cocotbext-sja1000: build the wheel =="
if ! tools=$(venv build maturin); then
  skip "everything: maturin cannot be had from PyPI: $why"; exit 0
fi
wheels="$root/target/wheels"
rm -f "$wheels"/cocotbext_sja1000-*.whl
if ! ( cd python/cocotbext-sja1000 && CARGO_TARGET_DIR="$root/target" "$tools/bin/python" -m maturin build --release -q -i "$tools/bin/python" ); then
  echo "test-python: FAILED: the cocotbext-sja1000 wheel does not build (maturin's output above)" >&2
  exit 1
fi
wheel=$(ls "$wheels"/cocotbext_sja1000-*.whl)
if [ "$bench" = 1 ]; then
  cargo build --release -q --bin cancosim
fi

# run_pair SIM COCOTB_SPEC NAME
run_pair() {
  local sim=$1 spec=$2 name=$3 py
  if ! command -v "$( [ "$sim" = icarus ] && echo iverilog || echo verilator)" >/dev/null; then
    skip "$name: $sim is not installed"; return
  fi
  if ! py=$(venv "$name" "$spec" python-can); then
    skip "$name: $spec or python-can cannot be had from PyPI: $why"; return
  fi
  if ! "$py/bin/python" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps "$wheel"; then
    echo "test-python: $name FAILED: the wheel does not install" >&2; fail=1; return
  fi
  local ex=python/cocotbext-sja1000/examples work
  work=$(mktemp -d "${TMPDIR:-/tmp}/cocotb-can.XXXXXX")
  echo "== $name: rtl/ (must pass) =="
  if "$py/bin/python" "$ex/run.py" --sim "$sim" --build-dir "$work/rtl" > "$work/rtl.log" 2>&1; then
    grep -E "TESTS=|run time" "$work/rtl.log"
  else
    cat "$work/rtl.log"; echo "test-python: $name FAILED on rtl/" >&2; fail=1
  fi
  echo "== $name: one-line mutant of rtl/ (must fail with the diagnosis) =="
  if "$py/bin/python" "$ex/run.py" --sim "$sim" --mutant --tests self_test_frame --build-dir "$work/mutant" > "$work/mutant.log" 2>&1; then
    sed -n '/^mutant caught/,/^Figures/p' "$work/mutant.log"
  else
    cat "$work/mutant.log"; echo "test-python: $name: the mutant was not diagnosed" >&2; fail=1
  fi
  if [ "$quick" = 1 ] && [ "$sim" = verilator ]; then
    echo "== $name: rtl/can_avalon, can_axi4lite, can_apb, can_regport, can_top_mcu: under Icarus only in --quick (scripts/test-python.sh runs them here too) =="
  else
    echo "== $name: rtl/can_avalon, the scoreboard fed by the Avalon-MM monitor (must pass) =="
    if "$py/bin/python" "$ex/run.py" --sim "$sim" --top can_avalon --build-dir "$work/avalon" > "$work/avalon.log" 2>&1; then
      grep -E "TESTS=|run time" "$work/avalon.log"
    else
      cat "$work/avalon.log"; echo "test-python: $name FAILED on rtl/can_avalon" >&2; fail=1
    fi
    echo "== $name: can_avalon on the mutant (must fail with the diagnosis, the marker at the failing read) =="
    if "$py/bin/python" "$ex/run.py" --sim "$sim" --top can_avalon --mutant --build-dir "$work/avalon-mutant" > "$work/avalon-mutant.log" 2>&1; then
      grep -E "^(mutant caught|marker:|Figures)" "$work/avalon-mutant.log"
    else
      cat "$work/avalon-mutant.log"; echo "test-python: $name: the can_avalon mutant was not diagnosed at its read" >&2; fail=1
    fi
    local t
    for t in av_slave_wait av_slave_pipe av_slave_fixed; do
      echo "== $name: the Avalon-MM master and monitor on $t (must pass) =="
      if "$py/bin/python" "$ex/run.py" --sim "$sim" --top "$t" --build-dir "$work/$t" > "$work/$t.log" 2>&1; then
        grep -E "TESTS=" "$work/$t.log"
      else
        cat "$work/$t.log"; echo "test-python: $name: the Avalon agents FAILED on $t" >&2; fail=1
      fi
    done
    local st
    for t in can_axi4lite can_apb can_regport can_top_mcu; do
      case $t in can_axi4lite | can_apb) st=amba_self_test_frame ;; *) st=bus_self_test_frame ;; esac
      echo "== $name: rtl/$t, the scoreboard fed by its bus monitor (must pass) =="
      if "$py/bin/python" "$ex/run.py" --sim "$sim" --top "$t" --build-dir "$work/$t" > "$work/$t.log" 2>&1; then
        grep -E "TESTS=|run time" "$work/$t.log"
      else
        cat "$work/$t.log"; echo "test-python: $name FAILED on rtl/$t" >&2; fail=1
      fi
      echo "== $name: $t on the mutant (must fail with the diagnosis, the marker at the failing read) =="
      if "$py/bin/python" "$ex/run.py" --sim "$sim" --top "$t" --mutant --tests "$st" --build-dir "$work/$t-mutant" > "$work/$t-mutant.log" 2>&1; then
        grep -E "^(mutant caught|marker:|Figures)" "$work/$t-mutant.log"
      else
        cat "$work/$t-mutant.log"; echo "test-python: $name: the $t mutant was not diagnosed at its read" >&2; fail=1
      fi
    done
  fi
  echo "== $name: the package README's example, as written =="
  if "$py/bin/python" "$ex/run.py" --sim "$sim" --readme --build-dir "$work/rtl" > "$work/readme.log" 2>&1; then
    grep -E "TESTS=|run time" "$work/readme.log"
  else
    cat "$work/readme.log"; echo "test-python: $name: the README's example FAILED" >&2; fail=1
  fi
  if [ "$bench" = 1 ]; then
    echo "== $name: without the scoreboard =="
    "$py/bin/python" "$ex/run.py" --sim "$sim" --no-scoreboard --build-dir "$work/nosb" > "$work/nosb.log" 2>&1 || { cat "$work/nosb.log"; fail=1; }
    grep -E "TESTS=|run time" "$work/nosb.log"
    local with without
    with=$(sed -n 's/^run time \([0-9.]*\) s.*/\1/p' "$work/rtl.log")
    without=$(sed -n 's/^run time \([0-9.]*\) s.*/\1/p' "$work/nosb.log")
    awk -v a="$with" -v b="$without" -v n="$name" 'BEGIN { if (b > 0) printf "bench %s: with the scoreboard %.2f s, without %.2f s, ratio %.2f (one run)\n", n, a, b, a / b }'
    # One test against the command line's co-simulation of the same
    # workload (examples/frame_exchange.toml), both wall times of one run.
    echo "== $name: frame_exchange_with_two_model_nodes against cancosim run =="
    "$py/bin/python" "$ex/run.py" --sim "$sim" --tests frame_exchange_with_two_model_nodes --build-dir "$work/one" > "$work/one.log" 2>&1 || { cat "$work/one.log"; fail=1; }
    local cocotb_s cli_s t0 t1
    cocotb_s=$(sed -n 's/^run time \([0-9.]*\) s.*/\1/p' "$work/one.log")
    target/release/cancosim run "$ex/frame_exchange.toml" > /dev/null  # Verilated model cached
    t0=$(date +%s.%N)
    target/release/cancosim run "$ex/frame_exchange.toml" > "$work/cli.log" 2>&1 || { cat "$work/cli.log"; fail=1; }
    t1=$(date +%s.%N)
    cli_s=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
    awk -v a="$cocotb_s" -v b="$cli_s" -v n="$name" 'BEGIN { if (b > 0) printf "bench %s: frame exchange in cocotb (with the scoreboard) %.2f s, cancosim run %.3f s, ratio %.0f (one run)\n", n, a, b, a / b }'
  fi
  rm -rf "$work"
}

run_pair icarus "cocotb>=2,<3" cocotb2-icarus
run_pair verilator "cocotb==1.9.2" cocotb19-verilator

if [ ${#skipped[@]} -gt 0 ]; then
  printf 'test-python: skipped: %s\n' "${skipped[@]}"
fi
if [ "$fail" = 1 ]; then
  echo "test-python: FAILED (see above)" >&2
fi
exit $fail
