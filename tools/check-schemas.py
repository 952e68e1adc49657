#!/usr/bin/env python3
"""check-schemas.py — cross-check schemas/ and job files with an independent
validator (Debian's python3-jsonschema), for CI (`make check-schemas`).

  1. every schemas/*.json is a valid JSON Schema 2020-12 document;
  2. every examples/*.json and examples/*/*.json job file {"process": P, "inputs": {...}} is valid:
     the file against schemas/job.schema.json (if present) and its "inputs"
     against schemas/P.inputs.schema.json;
  3. every tests/data/invalid/*.json job file is rejected by one of those.

"$ref"s between files are resolved by file name within schemas/ (the last
path segment of the referenced URI), as packd's embedded loader does.
Prints one "PASS name" / "FAIL name" line per file; exit status 1 on any
failure.
"""
import json
import os
import sys
import urllib.parse

import jsonschema
from jsonschema import Draft202012Validator

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCHEMAS = os.path.join(ROOT, "schemas")

try:  # jsonschema >= 4.18: the "referencing" library
    from referencing import Registry, Resource
    from referencing.exceptions import NoSuchResource
    from referencing.jsonschema import DRAFT202012
except ImportError:  # older jsonschema: RefResolver
    Registry = None


def load(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def schema_file_of(uri):
    """'https://x/y/pack.inputs.schema.json' or 'pack.inputs.schema.json' ->
    schemas/pack.inputs.schema.json (None if there is no such file)."""
    path = urllib.parse.urlsplit(uri).path
    name = path.rstrip("/").rsplit("/", 1)[-1]
    full = os.path.join(SCHEMAS, name)
    return full if name and os.path.isfile(full) else None


def make_validator(schema_path):
    schema = load(schema_path)
    name = os.path.basename(schema_path)
    if Registry is not None:
        def retrieve(uri):
            f = schema_file_of(uri)
            if f is None:
                raise NoSuchResource(ref=uri)
            return Resource.from_contents(load(f), default_specification=DRAFT202012)

        resource = Resource.from_contents(schema, default_specification=DRAFT202012)
        registry = Registry(retrieve=retrieve).with_resource(name, resource)
        base = name
        if isinstance(schema, dict) and isinstance(schema.get("$id"), str):
            registry = registry.with_resource(schema["$id"], resource)
            base = schema["$id"]
        resolver = registry.resolver(base_uri=base)
        return Draft202012Validator(schema, registry=registry), resolver.lookup

    store = {}
    for f in sorted(os.listdir(SCHEMAS)):
        if f.endswith(".json"):
            doc = load(os.path.join(SCHEMAS, f))
            store[f] = doc
            if isinstance(doc, dict) and isinstance(doc.get("$id"), str):
                store[doc["$id"]] = doc

    def handler(uri):
        f = schema_file_of(uri)
        if f is None:
            raise jsonschema.RefResolutionError("no schema file for " + uri)
        return load(f)

    base = schema.get("$id", name) if isinstance(schema, dict) else name
    resolver = jsonschema.RefResolver(base, schema, store=store,
                                      handlers={"": handler, "file": handler,
                                                "http": handler, "https": handler})
    return Draft202012Validator(schema, resolver=resolver), resolver.resolve


_validators = {}  # schema file name -> (validator, ref lookup) or (None, None)


def validator_and_lookup(schema_name):
    if schema_name not in _validators:
        path = os.path.join(SCHEMAS, schema_name)
        _validators[schema_name] = make_validator(path) if os.path.isfile(path) else (None, None)
    return _validators[schema_name]


def validator_for(schema_name):
    return validator_and_lookup(schema_name)[0]


def fmt_error(prefix, err):
    ptr = "".join("/" + str(p).replace("~", "~0").replace("/", "~1") for p in err.absolute_path)
    return "%s%s: %s" % (prefix, ptr, err.message)


def job_errors(path):
    """Reasons why the job file at `path` is invalid ([] if valid)."""
    try:
        job = load(path)
    except (OSError, ValueError) as e:
        return ["not readable JSON: %s" % e]
    errors = []
    envelope = validator_for("job.schema.json")
    if envelope is not None:
        errors += [fmt_error("", e) for e in envelope.iter_errors(job)]
    if not isinstance(job, dict):
        return errors or ["a job file must be an object"]
    process = job.get("process")
    if not isinstance(process, str):
        return errors or ["missing \"process\""]
    v = validator_for(process + ".inputs.schema.json")
    if v is None:
        return errors + ["no schema for process %r (schemas/%s.inputs.schema.json)"
                         % (process, process)]
    if "inputs" not in job:
        return errors or ["missing \"inputs\""]
    errors += [fmt_error("/inputs", e) for e in v.iter_errors(job["inputs"])]
    return errors


def json_files(d):
    full = os.path.join(ROOT, d)
    if not os.path.isdir(full):
        return []
    return [os.path.join(d, f) for f in sorted(os.listdir(full)) if f.endswith(".json")]


def example_files():
    """examples/*.json and the job files one folder down (examples/fe2/, ...)."""
    files = json_files("examples")
    top = os.path.join(ROOT, "examples")
    for d in sorted(os.listdir(top)) if os.path.isdir(top) else []:
        if os.path.isdir(os.path.join(top, d)):
            files += json_files(os.path.join("examples", d))
    return files


def report(ok, name, details=()):
    print("%s %s" % ("PASS" if ok else "FAIL", name))
    if not ok:
        for d in list(details)[:20]:
            print("    " + d)
    sys.stdout.flush()
    return ok


def main():
    failed = 0
    schemas = json_files("schemas")
    if not schemas:
        print("check-schemas: no schemas/*.json found", file=sys.stderr)
        return 2
    for rel in schemas:
        try:
            Draft202012Validator.check_schema(load(os.path.join(ROOT, rel)))
            problems = unresolved_refs(rel)  # check_schema does not follow refs
            ok = report(not problems, rel, problems)
        except jsonschema.SchemaError as e:
            ok = report(False, rel, [fmt_error("schema", e)])
        except (OSError, ValueError) as e:
            ok = report(False, rel, ["not readable JSON: %s" % e])
        failed += not ok
    for rel in example_files():
        errs = job_errors(os.path.join(ROOT, rel))
        failed += not report(not errs, rel, errs)
    for rel in json_files(os.path.join("tests", "data", "invalid")):
        errs = job_errors(os.path.join(ROOT, rel))
        failed += not report(bool(errs), rel, ["accepted, but must be rejected"])
    return 1 if failed else 0


def unresolved_refs(rel):
    """Every "$ref" in schema file `rel` must point at something."""
    v, lookup = validator_and_lookup(os.path.basename(rel))
    refs = []

    def walk(node):
        if isinstance(node, dict):
            r = node.get("$ref")
            if isinstance(r, str):
                refs.append(r)
            for k, x in node.items():
                if k not in ("const", "enum", "default", "examples"):
                    walk(x)
        elif isinstance(node, list):
            for x in node:
                walk(x)

    walk(v.schema)
    problems = []
    for r in refs:
        try:
            lookup(r)
        except Exception as e:  # any failure to resolve is a schema bug
            problems.append("unresolvable $ref %r: %s" % (r, e))
    return problems


if __name__ == "__main__":
    sys.exit(main())
