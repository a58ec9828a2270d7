#!/usr/bin/env bash
# Browser end-to-end test of `obscura serve` (tests/explore/e2e.mjs): builds the obscura
# binary, installs playwright-core from the npm registry when missing (no browser download:
# it drives Debian's /usr/bin/chromium), and runs the scenario. Screenshots go to
# tests/explore/out/ (or $OUT). Prints "N passed, N failed"; exits non-zero on a failure.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
export CHROMIUM="${CHROMIUM:-/usr/bin/chromium}"
if [ ! -x "$CHROMIUM" ]; then
    echo "tests/explore: $CHROMIUM is missing (apt-get install chromium)" >&2
    exit 1
fi
command -v node >/dev/null || { echo "tests/explore: node is missing (apt-get install nodejs npm)" >&2; exit 1; }
(cd "$root" && cargo build --quiet --bin obscura)
export OBSCURA="${OBSCURA:-$root/target/debug/obscura}"
if [ ! -d "$here/node_modules/playwright-core" ]; then
    (cd "$here" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --silent)
fi
exec node "$here/e2e.mjs"
