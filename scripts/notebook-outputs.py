"""Compares the text a notebook's code cells print, as committed, with the
same notebook executed again (issue 58 item 4: a re-run shows no diff).

    python scripts/notebook-outputs.py COMMITTED.ipynb EXECUTED.ipynb

Text is every stream (stdout, stderr), every result's and display's
`text/plain`, and every error's name and value. Pictures are left out:
they are drawn by matplotlib, whose bytes are not the project's to hold
fixed. Exits 1 with a unified diff per cell that differs, 0 when none do.
"""

import difflib
import json
import sys


def texts(path):
    """Per code cell, the text its outputs hold."""
    with open(path, encoding="utf-8") as f:
        cells = [c for c in json.load(f)["cells"] if c["cell_type"] == "code"]
    out = []
    for c in cells:
        parts = []
        for o in c.get("outputs", []):
            kind = o.get("output_type")
            if kind == "stream":
                parts.append("".join(o.get("text", "")))
            elif kind in ("execute_result", "display_data"):
                plain = o.get("data", {}).get("text/plain")
                if plain is not None and "image/png" not in o.get("data", {}):
                    parts.append("".join(plain))
            elif kind == "error":
                parts.append(f"{o.get('ename')}: {o.get('evalue')}")
        out.append("".join(parts))
    return out


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    committed, executed = sys.argv[1], sys.argv[2]
    a, b = texts(committed), texts(executed)
    if len(a) != len(b):
        sys.exit(f"{committed}: {len(a)} code cells, but {len(b)} were executed")
    differ = 0
    for i, (x, y) in enumerate(zip(a, b)):
        if x != y:
            differ += 1
            diff = difflib.unified_diff(
                x.splitlines(), y.splitlines(), f"{committed} cell {i} (committed)", f"cell {i} (executed again)", lineterm=""
            )
            print("\n".join(diff))
    if differ:
        print(
            f"{committed}: {differ} code cell(s) print other text when executed again; make them deterministic "
            f"(no wall times, temporary paths or dates) and commit the outputs "
            f"(jupyter nbconvert --to notebook --execute --inplace {committed})"
        )
        sys.exit(1)
    print(f"{committed}: {len(a)} code cells, the same text when executed again")


if __name__ == "__main__":
    main()
