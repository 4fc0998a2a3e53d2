#!/usr/bin/env python3
"""Validates diagnosis reports against docs/diagnosis.schema.json: the
reports named on the command line (each must validate) and every report
another test of the suite left in the temporary folder (mpm_*.json whose
"schema" is mpm.diagnosis/1). usage: validate_reports.py SCHEMA REPORT..."""
import glob, json, os, sys, tempfile
import jsonschema

schema = json.load(open(sys.argv[1]))
jsonschema.Draft7Validator.check_schema(schema)
validator = jsonschema.Draft7Validator(schema)
named = sys.argv[2:]
found = []
for path in glob.glob(os.path.join(tempfile.gettempdir(), "mpm_*.json")):
    try:
        doc = json.load(open(path))
    except (ValueError, OSError):
        continue  # a file another test is still writing, or not JSON
    if isinstance(doc, dict) and doc.get("schema") == "mpm.diagnosis/1":
        found.append(path)
bad = 0
for path in named + found:
    errors = sorted(validator.iter_errors(json.load(open(path))), key=lambda e: list(e.path))
    for e in errors[:5]:
        print("%s: %s: %s" % (path, "/".join(map(str, e.path)), e.message))
    bad += bool(errors)
print("%d report(s) validated (%d named, %d left by other tests), %d invalid" % (len(named) + len(found), len(named), len(found), bad))
sys.exit(1 if bad or not named else 0)
