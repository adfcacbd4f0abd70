#!/usr/bin/env bash
# The main job of the README: the DE2 thesis scenario on the bundled RTL,
# co-simulated against the golden model, with its diagnosis.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo run --release --quiet -p cancosim -- run tb/de2-thesis.toml "$@"
