#!/usr/bin/env bash
# Every test: the Rust workspace's, the Python package's against the command line's renders,
# and the browser explorer's end to end in headless Chromium. The README's test command;
# .ci/run calls it. Installs the Python package (and pytest, opencv-python-headless, numpy) into
# the active Python, and Debian's chromium, nodejs and npm when they are missing (as root).
set -uo pipefail
cd "$(dirname "$0")/.."
mkdir -p target
status=0

# The OpenCV cross-check (tests/it/opencv.rs) runs OpenCV's own projectPoints through python3.
python3 -m pip install --quiet pytest opencv-python-headless numpy || status=1

echo "== cargo test --workspace"
cargo test --workspace 2>&1 | tee target/test-rust.log
[ "${PIPESTATUS[0]}" -eq 0 ] || status=1

echo "== python: pip install ./crates/obscura-py, then pytest"
python3 -m pip install --quiet ./crates/obscura-py || status=1
cargo build --release --quiet --bin obscura || status=1
OBSCURA_BIN="$PWD/target/release/obscura" python3 -m pytest -q crates/obscura-py/tests 2>&1 \
  | tee target/test-python.log
[ "${PIPESTATUS[0]}" -eq 0 ] || status=1

echo "== browser: tests/explore/run.sh (obscura serve driven by headless Chromium)"
# Only what is missing: a machine whose Node.js comes from NodeSource has npm inside its nodejs
# package, and asking apt for Debian's npm beside it is refused as a conflict.
missing=()
[ -x /usr/bin/chromium ] || missing+=(chromium)
command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)
if [ "${#missing[@]}" -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    apt-get update -qq && apt-get install -y -qq "${missing[@]}" >/dev/null || status=1
  else
    echo "tests: ${missing[*]} needed (apt-get install ${missing[*]})" >&2
  fi
fi
bash tests/explore/run.sh 2>&1 | tee target/test-browser.log
[ "${PIPESTATUS[0]}" -eq 0 ] || status=1

# One closing line each: cargo's 'test result' lines summed, and pytest's own summary.
awk '/^test result:/ { p += $4; f += $6; i += $8 } END { printf "rust tests: %d passed, %d failed, %d skipped\n", p, f, i }' target/test-rust.log
echo "python tests: $(tail -n 1 target/test-python.log)"
echo "browser tests: $(tail -n 1 target/test-browser.log)"
exit "$status"
