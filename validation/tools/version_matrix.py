"""The table of ``bash scripts/test.sh --matrix``: one row per supported release, from the JUnit XML,
exit code, time and environment line each run left in ``out/matrix/`` (``<label>.xml``, ``.rc``,
``.env``; label "dev" is requirements.lock).  Writes matrix.md and matrix.json there and prints the table.

    python -m rt_lookdev.validation.tools.version_matrix out/matrix
"""
from __future__ import annotations

import json
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path


def _counts(xml_path):
    """(passed, failed, skipped) of a JUnit XML report (errors count as failed)."""
    root = ET.parse(xml_path).getroot()
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    total = sum(int(s.get("tests", 0)) for s in suites)
    failed = sum(int(s.get("failures", 0)) + int(s.get("errors", 0)) for s in suites)
    skipped = sum(int(s.get("skipped", 0)) for s in suites)
    return total - failed - skipped, failed, skipped


def rows(folder):
    out = []
    for rc_file in sorted(Path(folder).glob("*.rc"), key=lambda p: (p.stem != "dev", p.stem)):
        label = rc_file.stem
        rc, seconds = (int(x) for x in rc_file.read_text().split())
        env = (rc_file.with_suffix(".env").read_text().split() if rc_file.with_suffix(".env").exists()
               else ["?", "?", "?"])
        xml = rc_file.with_suffix(".xml")
        passed, failed, skipped = _counts(xml) if xml.exists() else (0, 0, 0)
        out.append({"environment": "requirements.lock" if label == "dev" else f"requirements/blender-{label}.lock",
                    "blender": env[0], "python": env[1], "numpy": env[2], "passed": passed, "failed": failed,
                    "skipped": skipped, "seconds": seconds, "exit_code": rc})
    return out


def markdown(table):
    lines = ["| environment | Blender (bpy) | Python | numpy | passed | failed | skipped | time |",
             "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['environment']} | {r['blender']} | {r['python']} | {r['numpy']} | {r['passed']} | "
              f"{r['failed']} | {r['skipped']} | {r['seconds']} s |" for r in table]
    return "\n".join(lines)


def main(argv):
    folder = Path(argv[0] if argv else "out/matrix")
    table = rows(folder)
    text = f"# Version matrix ({time.strftime('%Y-%m-%d')})\n\n" + markdown(table) + "\n"
    (folder / "matrix.md").write_text(text)
    (folder / "matrix.json").write_text(json.dumps(table, indent=1))
    print(text)
    return 0 if table and all(r["exit_code"] == 0 for r in table) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
