#!/bin/sh
# playwright.sh DIR — install the playwright-core that tests/integration/test_dashboard.sh
# drives Debian's chromium with into DIR/node_modules (make test's dependency step), once.
# Pinned: 1.59.1 runs on Debian 12's Node 18 (1.62 and later need Node 20).  Offline or
# without npm it leaves DIR/npm.log saying why, and the dashboard test skips with that line.
set -u
VERSION=1.59.1
DIR=$1
PW="$DIR/node_modules/playwright-core/package.json"
mkdir -p "$DIR"
grep -q "\"version\": \"$VERSION\"" "$PW" 2>/dev/null && exit 0
if ! command -v npm >/dev/null 2>&1; then
    echo "npm is not installed (apt-get install npm)" >"$DIR/npm.log"
    exit 0
fi
if ! PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm install --prefix "$DIR" --prefer-offline --no-audit \
    --no-fund --loglevel=error "playwright-core@$VERSION" >"$DIR/npm.log" 2>&1; then
    why=$(grep -m1 'reason:' "$DIR/npm.log" || grep -m1 'ERR!' "$DIR/npm.log" || tail -1 "$DIR/npm.log")
    echo "playwright.sh: npm install playwright-core@$VERSION failed: $why" >&2
    echo "npm install playwright-core@$VERSION failed: ${why:-no reason given}" >"$DIR/npm.log"
fi
exit 0
