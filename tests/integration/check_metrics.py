#!/usr/bin/env python3
"""check_metrics.py FILE — check a Prometheus text exposition (format 0.0.4)
the way a scraper reads it: every sample belongs to a family announced by
# HELP and # TYPE before it; names and labels are well formed; values parse;
counters end in _total; a histogram's buckets are cumulative, end at
le="+Inf" and equal its _count; no series appears twice.  Prints each problem
and exits 1 if there is one.  (promtool check metrics does this and more
where Debian's prometheus package is installed.)"""
import math
import re
import sys

NAME = re.compile(r"[a-zA-Z_:][a-zA-Z0-9_:]*$")
SAMPLE = re.compile(r'([a-zA-Z_:][a-zA-Z0-9_:]*)(\{(.*)\})? (\S+)( \d+)?$')
LABEL = re.compile(r'\s*([a-zA-Z_][a-zA-Z0-9_]*)="((?:[^"\\]|\\.)*)"\s*(,|$)')

problems = []
types, helps, seen = {}, {}, set()
hist = {}  # (family, labels without le) -> {"buckets": [(le, v)], "count": v}


def family_of(name):
    for suf in ("_bucket", "_sum", "_count"):
        if name.endswith(suf) and types.get(name[: -len(suf)]) in ("histogram", "summary"):
            return name[: -len(suf)]
    return name


for no, line in enumerate(open(sys.argv[1]).read().split("\n"), 1):
    if not line:
        continue
    if line.startswith("# HELP ") or line.startswith("# TYPE "):
        parts = line.split(" ", 3)
        if len(parts) < 4 or not NAME.match(parts[2]):
            problems.append("line %d: malformed %s" % (no, line))
            continue
        if parts[1] == "TYPE":
            if parts[3] not in ("counter", "gauge", "histogram", "summary", "untyped"):
                problems.append("line %d: unknown type %s" % (no, parts[3]))
            if parts[2] in types:
                problems.append("line %d: second TYPE for %s" % (no, parts[2]))
            types[parts[2]] = parts[3]
            if parts[3] == "counter" and not parts[2].endswith("_total"):
                problems.append("line %d: counter %s does not end in _total" % (no, parts[2]))
        else:
            helps[parts[2]] = parts[3]
        continue
    if line.startswith("#"):
        continue
    m = SAMPLE.match(line)
    if not m:
        problems.append("line %d: not a sample: %r" % (no, line))
        continue
    name, labels_text, value = m.group(1), m.group(3) or "", m.group(4)
    labels, pos = {}, 0
    while pos < len(labels_text):
        lm = LABEL.match(labels_text, pos)
        if not lm:
            problems.append("line %d: bad labels %r" % (no, labels_text))
            break
        labels[lm.group(1)] = lm.group(2)
        pos = lm.end()
    try:
        v = float(value)
    except ValueError:
        problems.append("line %d: bad value %r" % (no, value))
        continue
    fam = family_of(name)
    if fam not in types or fam not in helps:
        problems.append("line %d: %s has no # TYPE and # HELP before it" % (no, name))
    key = (name, tuple(sorted(labels.items())))
    if key in seen:
        problems.append("line %d: duplicate series %s%s" % (no, name, labels))
    seen.add(key)
    if types.get(fam) == "counter" and (v < 0 or math.isnan(v)):
        problems.append("line %d: counter %s is %s" % (no, name, value))
    if types.get(fam) == "histogram":
        base = tuple(sorted((k, x) for k, x in labels.items() if k != "le"))
        h = hist.setdefault((fam, base), {"buckets": [], "count": None})
        if name.endswith("_bucket"):
            if "le" not in labels:
                problems.append("line %d: bucket without le" % no)
            else:
                h["buckets"].append((float(labels["le"]), v))
        elif name.endswith("_count"):
            h["count"] = v

for (fam, base), h in hist.items():
    b = h["buckets"]
    if not b or b[-1][0] != math.inf:
        problems.append("%s%s: buckets do not end at +Inf" % (fam, dict(base)))
        continue
    if any(b[i][0] >= b[i + 1][0] or b[i][1] > b[i + 1][1] for i in range(len(b) - 1)):
        problems.append("%s%s: buckets not increasing and cumulative" % (fam, dict(base)))
    if h["count"] != b[-1][1]:
        problems.append("%s%s: _count %s != +Inf bucket %s" % (fam, dict(base), h["count"], b[-1][1]))

for p in problems:
    print(p)
sys.exit(1 if problems else 0)
