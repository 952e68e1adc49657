#!/bin/sh
# h5digest.sh FILE.h5 — one SHA-256 line per dataset of a result file, over
# its raw little-endian bytes (h5dump -b), skipping the wall-clock figures
# (/observables/timing/*, *seconds*, *per_second) that differ run to run.
# Two results of the same job with equal output computed the same numbers.
# A dataset with a second name (the step and time an H5MD element shares
# through hard links: h5ls says "Dataset, same as ...") is listed once, under
# the name h5ls meets first.
f=$1
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
h5ls -r "$f" | awk '$2 == "Dataset" { print $1 }' | sort |
    grep -vE '^/observables/timing/|seconds|per_second' |
    while read -r d; do
        h5dump -d "$d" -b LE -o "$tmp" "$f" >/dev/null 2>&1 || { echo "$d unreadable"; continue; }
        echo "$d $(sha256sum <"$tmp" | cut -c1-16)"
    done
