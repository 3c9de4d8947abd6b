"""One mesh of a corpus run, in a process of its own (``conemesh.batch`` starts it), so that a
crash or a timeout costs a row of the table, not the run.

``python -m conemesh._one INPUT OUTPUT RESULT.json ARG...``: reads INPUT, remeshes it with the
``conemesh remesh`` flags ARG..., writes OUTPUT and RESULT.json (the report, the SHA-256 of
OUTPUT's bytes). Exit 0 on success; 3 when conemesh refused the input or the options
(RESULT.json then holds the exception's class and message); anything else is a crash.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys

REFUSED = 3


def main(argv: list[str]) -> int:
    input_path, output_path, result_path, *args = argv
    import conemesh

    try:
        V, F = conemesh.read(input_path)
        (U, G), report = conemesh._conemesh.remesh(
            conemesh._vertices(V), conemesh._faces(F), None, None, args + ["--quiet"]
        )
        conemesh.write(output_path, U, G)
    except conemesh.Error as e:
        doc = {"error": f"{type(e).__name__}: {e}"}
        _write_json(result_path, doc)
        return REFUSED
    report = json.loads(report)
    with open(output_path, "rb") as fh:
        report["output_sha256"] = hashlib.sha256(fh.read()).hexdigest()
    _write_json(result_path, report)
    return 0


def _write_json(path: str, doc: dict) -> None:
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as fh:
        json.dump(doc, fh)
    os.replace(tmp, path)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
