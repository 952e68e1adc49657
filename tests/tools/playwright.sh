#!/bin/sh
# playwright.sh DIR — install the npm test tools into DIR/node_modules (make test's
# dependency step), once each: playwright-core, with which tests/integration/test_dashboard.sh
# and test_serve_conventions.sh drive Debian's chromium, and @redocly/cli, which
# test_serve_conventions.sh lints schemas/openapi.json with.  Pinned to versions that run
# on Debian 12's Node 18 (playwright-core 1.62 and later, @redocly/cli 2.x need Node 20).
# Offline or without npm it leaves DIR/npm.log saying why, and the tests skip with that line.
set -u
DIR=$1
mkdir -p "$DIR"
if ! command -v npm >/dev/null 2>&1; then
    echo "npm is not installed (apt-get install npm)" >"$DIR/npm.log"
    exit 0
fi
for pkg in playwright-core@1.59.1 @redocly/cli@1.34.20; do
    name=${pkg%@*} version=${pkg##*@}
    grep -q "\"version\": \"$version\"" "$DIR/node_modules/$name/package.json" 2>/dev/null && continue
    if ! PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm install --prefix "$DIR" --prefer-offline --no-audit \
        --no-fund --loglevel=error "$pkg" >"$DIR/npm.log" 2>&1; then
        why=$(grep -m1 'reason:' "$DIR/npm.log" || grep -m1 'ERR!' "$DIR/npm.log" || tail -1 "$DIR/npm.log")
        echo "playwright.sh: npm install $pkg failed: $why" >&2
        echo "npm install $pkg failed: ${why:-no reason given}" >"$DIR/npm.log"
    fi
done
exit 0
