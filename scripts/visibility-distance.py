#!/usr/bin/env python3
"""Visibility against viewing distance of built stimulus sets (docs/stimuli.md, "Visibility against viewing distance
of the shipped specs"), from the visibility.json that `skinlab stimuli visibility DIR` writes (ColorVideoVDP of each
condition against its block's reference on the presented images, at each pixels per degree).

Usage: visibility-distance.py [--conditions] SET_DIR [SET_DIR ...]

Prints a Markdown table, one row per set and block: the number of conditions, the most visible condition's JOD at
each pixels per degree, how many conditions lie below 9 JOD (1 JOD from the reference) there, and up to where the
most visible condition stays below 9 JOD. With --conditions, one row per condition instead: its JOD at each pixels
per degree and up to where it stays below 9 JOD."""
import json
import sys


def limit_text(row, ppd):
    if row["visible_everywhere"]:
        return f"beyond {ppd[-1]:g} ppd"
    if row["invisible_everywhere"]:
        return f"not at {ppd[0]:g} ppd"
    limit = row.get("one_jod_limit")
    if not limit:
        return "—"
    text = f"{limit['pixels_per_degree']:.0f} ppd"
    if "distance_m" in limit:
        text += f" ({limit['distance_m']:.2f} m)"
    return text


def header(v, first):
    ppd = v["pixels_per_degree"]
    distance = v.get("distance_m") or [None] * len(ppd)
    cells = [f"{p:g} ppd" + (f" ({d:.2f} m)" if d else "") for p, d in zip(ppd, distance)]
    return cells


def main(argv):
    conditions = "--conditions" in argv
    folders = [a for a in argv if a != "--conditions"]
    if not folders:
        print(__doc__, file=sys.stderr)
        return 2
    printed = False
    for folder in folders:
        with open(f"{folder}/visibility.json") as f:
            v = json.load(f)
        with open(f"{folder}/manifest.json") as f:
            name = json.load(f)["set"]
        ppd = v["pixels_per_degree"]
        if not printed:
            cells = header(v, True)
            if conditions:
                print("| set | block | condition | " + " | ".join(cells) + " | below 9 JOD up to |")
                print("|---|---|---|" + "---|" * len(cells) + "---|")
            else:
                print("| set | block | conditions | most visible: " + " | ".join(cells) +
                      " | below 9 JOD (of all) at each ppd | most visible below 9 JOD up to |")
                print("|---|---|---|" + "---|" * len(cells) + "---|---|")
            printed = True
        blocks = []
        for row in v["rows"]:
            if row["block"] not in blocks:
                blocks.append(row["block"])
        for block in blocks:
            rows = [r for r in v["rows"] if r["block"] == block]
            if conditions:
                for r in rows:
                    print(f"| {name} | {block} | {r['stimulus']} | " + " | ".join(f"{j:.2f}" for j in r["jod"]) +
                          f" | {limit_text(r, ppd)} |")
                continue
            worst = min(rows, key=lambda r: min(r["jod"]))
            counts = [sum(1 for r in rows if r["jod"][k] < v["visible_below_jod"]) for k in range(len(ppd))]
            print(f"| {name} | {block} | {len(rows)} | " +
                  " | ".join(f"{min(r['jod'][k] for r in rows):.2f}" for k in range(len(ppd))) +
                  f" | {' / '.join(str(c) for c in counts)} | {worst['stimulus']}: {limit_text(worst, ppd)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
