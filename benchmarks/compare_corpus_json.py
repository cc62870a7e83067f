"""Compare two ``inertia-tool robot FOLDER --json`` outputs (a corpus) link by link: are the answers the same?

A speed change to the robot pipeline must not change any answer (issues 23/25).  This reads two corpus reports
(``command`` ``robot-corpus``) and compares, for every model (by its ``source``) and every link (by position and
name): ``mass``, ``volume``, ``center_of_mass``, ``inertia``, ``method``, ``uncertainty`` and ``problem``, exactly
(floats to the bit, as JSON keeps them: ``repr`` round-trips), and the models' own ``problem``.  The links'
warnings are compared too, but counted apart (a parallel run may word nothing differently, yet a warning is not an
answer).

    python benchmarks/compare_corpus_json.py BEFORE.json AFTER.json

Prints the counts and the first differences; exit code 1 when an answer differs.
"""

from __future__ import annotations

import argparse
import json
import sys

FIELDS = ("mass", "volume", "center_of_mass", "inertia", "method", "uncertainty", "problem")


def _models(path: str) -> dict:
    with open(path, encoding="utf-8") as fh:
        report = json.load(fh)
    if report.get("command") != "robot-corpus":
        raise SystemExit(f"{path}: expected the JSON of `inertia-tool robot FOLDER --json`, got command "
                         f"{report.get('command')!r}")
    return {model["source"]: model for model in report["models"]}


def compare(before: dict, after: dict) -> tuple[int, int, int, list]:
    """(links compared, links whose answer differs, links whose warnings differ, lines describing differences)."""
    lines: list = []
    links = answers = worded = 0
    for source in sorted(set(before) | set(after)):
        a, b = before.get(source), after.get(source)
        if a is None or b is None:
            lines.append(f"{source}: only in {'after' if a is None else 'before'}")
            answers += 1
            continue
        if a.get("problem") != b.get("problem"):
            lines.append(f"{source}: model problem {a.get('problem')!r} -> {b.get('problem')!r}")
            answers += 1
        la, lb = a.get("links") or [], b.get("links") or []
        if len(la) != len(lb):
            lines.append(f"{source}: {len(la)} links -> {len(lb)}")
            answers += 1
            continue
        for x, y in zip(la, lb):
            links += 1
            changed = [k for k in FIELDS if x.get(k) != y.get(k)]
            if x.get("name") != y.get("name") or changed:
                answers += 1
                lines.append(f"{source}: link {x.get('name')!r}: {', '.join(changed) or 'name'} differ")
            elif x.get("warnings") != y.get("warnings"):
                worded += 1
    return links, answers, worded, lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--show", type=int, default=20, help="differences listed (default 20)")
    args = parser.parse_args(argv)
    links, answers, worded, lines = compare(_models(args.before), _models(args.after))
    print(f"{links} links compared: {answers} answers differ, {worded} links' warnings differ")
    for line in lines[:args.show]:
        print("  " + line)
    return 1 if answers else 0


if __name__ == "__main__":
    sys.exit(main())
