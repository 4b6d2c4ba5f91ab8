#!/usr/bin/env bash
# The test command: installs what is missing, then checks formatting and lints, and runs
# every test on the Vulkan device (lavapipe on a machine without a GPU) with the
# validation layer on. Any validation message fails the test that caused it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cargo fmt --all -- --check
cargo clippy --workspace --all-targets --quiet -- -D warnings
DVR_VALIDATION=1 cargo test --workspace "$@"
