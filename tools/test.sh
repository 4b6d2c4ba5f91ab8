#!/usr/bin/env bash
# The test command: installs what is missing, then checks formatting and lints, and runs
# every test on the Vulkan device (lavapipe on a machine without a GPU) with the
# validation layer on. Any validation message fails the test that caused it. Then the
# docs: every generated results table against the CSVs it comes from
# (tools/results.py --check), the book built by mdBook with the API reference (cargo
# doc, pdoc), and its links, README's and OVERVIEW.md's checked offline
# (tools/check_docs.py); the book's command-line page is
# checked against `dvr --help` by cargo test (tests/cli_doc.rs). Last, the Python
# package: its wheel built and installed into a virtual environment (target/py), and
# python/tests run against the installed wheel.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh --tests
cargo fmt --all -- --check
cargo clippy --workspace --all-targets --quiet -- -D warnings
DVR_VALIDATION=1 cargo test --workspace "$@"

# The docs: the results pages against their CSVs, the book (with the Rust API reference;
# a broken intra-doc link fails), its links once the Python reference joins it below.
python3 tools/results.py --check
rm -rf docs/book
mdbook build docs >/dev/null
RUSTDOCFLAGS="-D rustdoc::broken_intra_doc_links" cargo doc --workspace --no-deps --quiet
mkdir -p docs/book/api
cp -r target/doc docs/book/api/rust

py=target/py/bin/python
[ -x "$py" ] || python3 -m venv target/py
"$py" -m pip install --quiet --disable-pip-version-check -r python/requirements-test.txt
# The dev profile shares the engine's build with `cargo test` above.
rm -rf target/wheels
"$py" -m maturin build --quiet -m python/Cargo.toml -o target/wheels
"$py" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps target/wheels/dvr-*.whl
# The Python reference from the installed package's docstrings, then the book's links.
"$py" -m pdoc dvr dvr.viewer -o docs/book/api/python >/dev/null 2>&1
python3 tools/check_docs.py
# From outside the checkout, so `import dvr` is the installed wheel, not python/dvr.
(cd target && DVR_VALIDATION=1 DVR_BIN="$PWD/debug/dvr" "$PWD/py/bin/python" -m pytest -q ../python/tests)
