#!/usr/bin/env python3
"""ref_walk.py BASE — resolve every "$ref" of every process description of
the service at BASE, as a JSON Schema 2020-12 client does: each schema of a
description (an input's "schema", "inputsSchema", an output's "schema") is a
document of its own whose base URI is the description's URL; an "$id" opens
an embedded resource at its URI (resolved against the enclosing base); a
reference resolves against its base to an embedded resource and a JSON
pointer in it, or else to a URL this service serves (fetched, 200 JSON).
Prints one FAIL line per reference that does not resolve and ends with
"refs N unresolved M"; exits 1 if any failed."""
import json
import sys
import urllib.error
import urllib.parse
import urllib.request

BASE = sys.argv[1].rstrip("/")


def get(url):
    with urllib.request.urlopen(url, timeout=20) as r:
        return json.load(r)


def pointer(doc, frag):
    node = doc
    for part in frag.split("/")[1:] if frag else []:
        part = urllib.parse.unquote(part).replace("~1", "/").replace("~0", "~")
        if isinstance(node, list):
            node = node[int(part)]
        elif isinstance(node, dict) and part in node:
            node = node[part]
        else:
            raise KeyError(frag)
    return node


def walk(node, base, resources, refs):
    """Register embedded resources, collect (base, ref) pairs."""
    if isinstance(node, list):
        for e in node:
            walk(e, base, resources, refs)
        return
    if not isinstance(node, dict):
        return
    if isinstance(node.get("$id"), str):
        base = urllib.parse.urldefrag(urllib.parse.urljoin(base, node["$id"]))[0]
        resources[base] = node
    if isinstance(node.get("$ref"), str):
        refs.append((base, node["$ref"]))
    for k, v in node.items():
        if k not in ("const", "enum", "default", "examples"):
            walk(v, base, resources, refs)


fetched = {}


def resolve(base, ref, resources):
    url, frag = urllib.parse.urldefrag(urllib.parse.urljoin(base, ref))
    if url in resources:
        return pointer(resources[url], frag)
    if not url.startswith(BASE + "/"):
        raise LookupError("neither embedded nor served here: " + url)
    if url not in fetched:
        fetched[url] = get(url)  # raises on 404
    return pointer(fetched[url], frag)


total = bad = 0
for summary in get(BASE + "/processes")["processes"]:
    url = BASE + "/processes/" + summary["id"]
    desc = get(url)
    schemas = [("inputsSchema", desc.get("inputsSchema"))]
    for kind in ("inputs", "outputs"):
        for name, io in (desc.get(kind) or {}).items():
            schemas.append((f"{kind}/{name}/schema", io.get("schema")))
    for where, schema in schemas:
        if schema is None:
            continue
        resources, refs = {url: schema}, []
        walk(schema, url, resources, refs)
        for b, ref in refs:
            total += 1
            try:
                resolve(b, ref, resources)
            except (LookupError, KeyError, ValueError, IndexError, urllib.error.URLError) as e:
                bad += 1
                print(f"FAIL {summary['id']} {where}: $ref {ref} ({type(e).__name__}: {e})")
print(f"refs {total} unresolved {bad}")
sys.exit(1 if bad or not total else 0)
