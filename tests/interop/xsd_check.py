"""Validates NodeSet2 files against an XML schema (UANodeSet.xsd) with the xmlschema package.

usage: .venv/bin/python tests/interop/xsd_check.py SCHEMA FILE...

Prints ``<file>: N errors`` per file, then up to five errors each (with their path in the document);
exits 1 if any file has an error.
"""

import sys

import xmlschema


def main() -> int:
    schema = xmlschema.XMLSchema(sys.argv[1])
    failed = 0
    for path in sys.argv[2:]:
        errors = list(schema.iter_errors(path))
        print(f"{path}: {len(errors)} errors")
        for error in errors[:5]:
            print(f"  at {error.path}: {error.reason}")
        failed += bool(errors)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
