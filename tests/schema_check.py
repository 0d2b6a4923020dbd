"""What the schema checks share: a draft 2020-12 validator for a schema file, and a document's
errors against it one line each. Debian's python3 with python3-jsonschema (`make deps`)."""

import json
import sys
from pathlib import Path

try:
    import jsonschema
except ImportError:
    print("FAIL: python3-jsonschema is missing (make deps)")
    sys.exit(1)

DRAFT_2020_12 = "https://json-schema.org/draft/2020-12/schema"


def load_validator(path):
    """Returns (validator, problems). The validator is None when the file is not a valid draft
    2020-12 schema; problems also lists a $schema other than draft 2020-12."""
    schema = json.loads(Path(path).read_text())
    problems = []
    if schema.get("$schema") != DRAFT_2020_12:
        problems.append(f"{path}: $schema is not draft 2020-12")
    try:
        jsonschema.Draft202012Validator.check_schema(schema)
    except jsonschema.exceptions.SchemaError as e:
        problems.append(f"{path}: not a valid draft 2020-12 schema: {e.message}")
        return None, problems
    return jsonschema.Draft202012Validator(schema), problems


def schema_errors(validator, doc):
    """Each error as 'path/in/doc: message' ('(top)' for the document itself)."""
    return [f"{'/'.join(str(p) for p in e.absolute_path) or '(top)'}: {e.message}"
            for e in validator.iter_errors(doc)]
