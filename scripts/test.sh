#!/usr/bin/env bash
# The test command: formatting, lints, then every test (unit, integration, the CI experiment's
# regression thresholds, GPU tests on whatever Vulkan adapter exists -- lavapipe in CI).
set -euo pipefail
cd "$(dirname "$0")/.."
# Mesa's software driver warns about a missing XDG_RUNTIME_DIR on headless machines.
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
cargo fmt --check
cargo clippy --release --all-targets -- -D warnings
cargo clippy --release --all-targets --features test-hooks -- -D warnings
cargo test --release --features test-hooks
