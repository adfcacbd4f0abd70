#!/usr/bin/env bash
# Installs what the project needs on a fresh Debian machine: Verilator (the
# co-simulation DUT build), Icarus Verilog (RTL compile check, bench) and
# Yosys (resource estimate), SDCC (8051 header check), GHDL (VHDL cores),
# lcov (genhtml for `regress --coverage`), dtc (the generated device-tree node). Rust comes with the machine (rustup).
# Fails with one clear sentence when something cannot be had.
set -euo pipefail

need_pkgs=()
command -v verilator >/dev/null 2>&1 || need_pkgs+=(verilator)
command -v iverilog  >/dev/null 2>&1 || need_pkgs+=(iverilog)
command -v yosys     >/dev/null 2>&1 || need_pkgs+=(yosys)
# verilator needs a C++ compiler and make for the models it generates.
command -v g++  >/dev/null 2>&1 || need_pkgs+=(g++)
command -v make >/dev/null 2>&1 || need_pkgs+=(make)
command -v gcc  >/dev/null 2>&1 || need_pkgs+=(gcc)
# tclsh sources the generated _hw.tcl in the generator tests.
command -v tclsh >/dev/null 2>&1 || need_pkgs+=(tcl)
# sdcc compiles the generated 8051 header in the generator tests.
command -v sdcc  >/dev/null 2>&1 || need_pkgs+=(sdcc)
# ghdl turns VHDL cores into Verilog (ghdl --synth) for Verilator.
command -v ghdl  >/dev/null 2>&1 || need_pkgs+=(ghdl)
# lcov's genhtml writes the HTML report of `regress --coverage`.
command -v genhtml >/dev/null 2>&1 || need_pkgs+=(lcov)
# dtc compiles the generated device-tree node in the generator tests.
command -v dtc >/dev/null 2>&1 || need_pkgs+=(device-tree-compiler)

if [ ${#need_pkgs[@]} -gt 0 ]; then
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "setup: missing ${need_pkgs[*]} and no apt-get here; install them (Verilator >= 5.006) and re-run." >&2
    exit 1
  fi
  SUDO=""
  if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
      echo "setup: missing ${need_pkgs[*]}; run as root or install them with apt-get." >&2; exit 1
    fi
  fi
  echo "setup: installing ${need_pkgs[*]} from Debian's packages..." >&2
  if ! { $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_pkgs[@]}" >/dev/null; }; then
    echo "setup: apt-get could not install ${need_pkgs[*]}; check the package mirror and re-run." >&2
    exit 1
  fi
fi

# Optional viewers for the VCD, GTKWave and HTML outputs, checked by tests that skip
# without them: headless Chromium (renders `regress --html`), GTKWave and
# Xvfb, xwd and netpbm (open the .gtkw views and take a screenshot). About
# 90 MB download, 310 MB on disk, under 2 min on this machine kind; SETUP_VIEWERS=0 leaves them out. A failure here
# only warns: the kit works without them.
if [ "${SETUP_VIEWERS:-1}" != 0 ] && command -v apt-get >/dev/null 2>&1; then
  view_pkgs=()
  command -v chromium >/dev/null 2>&1 || view_pkgs+=(chromium)
  command -v gtkwave  >/dev/null 2>&1 || view_pkgs+=(gtkwave)
  command -v Xvfb     >/dev/null 2>&1 || view_pkgs+=(xvfb xauth)
  command -v xwd      >/dev/null 2>&1 || view_pkgs+=(x11-apps)
  command -v xwdtopnm >/dev/null 2>&1 || view_pkgs+=(netpbm)
  if [ ${#view_pkgs[@]} -gt 0 ]; then
    SUDO=""; [ "$(id -u)" != 0 ] && command -v sudo >/dev/null 2>&1 && SUDO="sudo"
    echo "setup: installing ${view_pkgs[*]} (optional viewers, SETUP_VIEWERS=0 to skip)..." >&2
    if ! { $SUDO apt-get update -qq >/dev/null 2>&1; DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${view_pkgs[@]}" >/dev/null 2>&1; }; then
      echo "setup: warning: could not install ${view_pkgs[*]}; the HTML and GTKWave view tests will skip their browser and screenshot parts." >&2
    fi
  fi
fi

if ! command -v cargo >/dev/null 2>&1; then
  echo "setup: cargo not found; install Rust (rustup) and re-run." >&2
  exit 1
fi
