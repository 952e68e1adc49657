#!/bin/sh
# vendor-swagger-ui.sh — refresh the Swagger UI files that packd compiles in
# (web/swagger-ui-*: the interactive API page at /api?f=html).  They are kept
# in the repository, so building packd needs no registry; this script is run
# by hand to change the version: it fetches the pinned swagger-ui-dist
# package with npm, checks its SHA-256 and copies the browser bundle, its
# stylesheet, its LICENSE (Apache-2.0) and NOTICE.  Unused: the source maps,
# the ES modules, the standalone preset (~10 MB).
set -eu
VERSION=5.35.0
SHA256=1b8e891893404ea4c3558b6a87e2a3e494e7eedba41168c2ece5800a391a6ea6
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
(cd "$tmp" && npm pack --silent "swagger-ui-dist@$VERSION" >/dev/null)
echo "$SHA256  $tmp/swagger-ui-dist-$VERSION.tgz" | sha256sum -c --quiet
tar -xzf "$tmp/swagger-ui-dist-$VERSION.tgz" -C "$tmp"
cp "$tmp/package/swagger-ui-bundle.js" web/swagger-ui-bundle.js
cp "$tmp/package/swagger-ui.css" web/swagger-ui.css
cp "$tmp/package/LICENSE" web/swagger-ui-LICENSE.txt
cp "$tmp/package/NOTICE" web/swagger-ui-NOTICE.txt
echo "swagger-ui-dist $VERSION copied to web/"
