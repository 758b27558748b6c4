#!/usr/bin/env python3
"""Predicted visibility of built stimulus sets (docs/stimuli.md, "Measured visibility of the shipped specs"), from
the "predicted" JOD that `skinlab stimuli build` records in each manifest (ColorVideoVDP against the block's
reference, on the presented images).

Usage: visibility-table.py SET_DIR [SET_DIR ...]

Prints two Markdown tables:
  blocks      per set and block: presented size, number of conditions, the best and worst condition's JOD against
              the reference, and the spread (best − worst; the goal is at least 1 JOD);
  extensions  per set, block and extended stimulus: its JOD, the JOD of the same stimulus without the extension and
              the effect (with − without; the goal is a magnitude of at least 0.3 JOD).
A stimulus is "extended" when its factors are those of another stimulus of the same block (same method) plus
extension keys, or when it differs from one by sss.follow_surface (true = with). Without its extension keys, an
include's stimulus keeps the scene's default (follow-surface on): its base is the stimulus with the same method
and follow-surface on, or the one with no further factors; an extension with follow-surface off is compared with the
same method with follow-surface off. Transmittance (transmittance.enabled true, with any other transmittance.* keys
such as its translucency) is compared with the same stimulus with transmittance.enabled false."""
import json
import sys

FACTORIAL_IGNORED = {"scene", "view"}


def load(folder):
    with open(f"{folder}/manifest.json") as f:
        return json.load(f)


def factors_of(s):
    """The factors that tell the stimuli of a block apart (block-wide ones, like scene, view or a depth gap, left out)."""
    return {k: v for k, v in s["factors"].items() if k not in FACTORIAL_IGNORED and k not in s.get("_block_keys", ())}


def presented(s):
    p = s.get("presentation")
    if not p:
        return f"{s['width']}×{s['height']}"
    c, m = p["crop"], p["magnification"]
    r = p["render"]
    whole = c["x"] == 0 and c["y"] == 0 and c["width"] == r["width"] and c["height"] == r["height"]
    crop = "whole" if whole else f"crop {c['width']}×{c['height']}"
    return f"{crop} ×{m} = {p['presented']['width']}×{p['presented']['height']}"


def base_of(s, block_stimuli):
    """The stimulus `s` extends, and the name of the extension; None when it extends nothing."""
    f = factors_of(s)
    method = f.get("method")
    # transmittance on (with its own keys, e.g. a translucency) against the same stimulus with it off
    if f.get("transmittance.enabled") == "true":
        own = {k: v for k, v in f.items() if k.startswith("transmittance.") and k != "transmittance.enabled"}
        rest = {k: v for k, v in f.items() if not k.startswith("transmittance.")}
        for o in block_stimuli:
            g = factors_of(o)
            if g.get("transmittance.enabled") == "false" and {
                k: v for k, v in g.items() if not k.startswith("transmittance.")
            } == rest:
                details = "".join(f", {k.removeprefix('transmittance.')}={v}" for k, v in sorted(own.items()))
                return o, f"transmittance{details}"
        return None, None
    # follow-surface as a factor level: with (true) against without (false), the rest equal
    if f.get("sss.follow_surface") == "true":
        for o in block_stimuli:
            g = factors_of(o)
            if g.get("sss.follow_surface") == "false" and {k: v for k, v in g.items() if k != "sss.follow_surface"} == {
                k: v for k, v in f.items() if k != "sss.follow_surface"
            }:
                return o, "follow-surface"
    extra = {k: v for k, v in f.items() if k not in ("method", "sss.follow_surface")}
    candidates = []
    for o in block_stimuli:
        if o is s:
            continue
        g = factors_of(o)
        if g.get("method") != method:
            continue
        g_extra = {k: v for k, v in g.items() if k not in ("method", "sss.follow_surface")}
        if g_extra:
            continue
        if g.get("sss.follow_surface", "true") != "true":
            continue
        candidates.append(o)
    if extra and f.get("sss.follow_surface") == "false":
        # an extension without follow-surface: its base is the same method without follow-surface
        for o in block_stimuli:
            g = factors_of(o)
            if o is not s and g == {"method": method, "sss.follow_surface": "false"}:
                name = " + ".join(f"{k.removeprefix('sss.')}={v}" for k, v in sorted(extra.items()))
                return o, f"{name} (follow-surface off)"
        return None, None
    if f.get("sss.follow_surface") == "false" and not extra:
        # an include without follow-surface: its base is the method with follow-surface (the default)
        return (candidates[0], "without follow-surface") if candidates else (None, None)
    if not extra:
        return None, None
    name = " + ".join(f"{k.removeprefix('sss.')}={v}" for k, v in sorted(extra.items()))
    return (candidates[0], name) if candidates else (None, None)


def main():
    block_rows, effect_rows, seen = [], [], set()
    for folder in sys.argv[1:]:
        m = load(folder)
        blocks = {}
        for s in m["stimuli"]:
            blocks.setdefault(s["block"], []).append(s)
        for block, stimuli in blocks.items():
            tests = [s for s in stimuli if not s["reference"] and "predicted" in s]
            keys = {k for s in tests for k in s["factors"]}
            constant = {k for k in keys if len({s["factors"].get(k) for s in tests}) == 1}
            for s in tests:
                s["_block_keys"] = constant
            if not tests:
                continue
            best = max(tests, key=lambda s: s["predicted"]["jod"])
            worst = min(tests, key=lambda s: s["predicted"]["jod"])
            spread = best["predicted"]["jod"] - worst["predicted"]["jod"]
            block_rows.append(
                f"| {m['set']} | {block} | {presented(tests[0])} | {len(tests)} | {best['predicted']['jod']:.2f} "
                f"({best['id']}) | {worst['predicted']['jod']:.2f} ({worst['id']}) | {spread:.2f} |"
                f" {'yes' if spread >= 1.0 else 'no'} |"
            )
            for s in tests:
                base, name = base_of(s, tests)
                if base is None:
                    continue
                effect = s["predicted"]["jod"] - base["predicted"]["jod"]
                if name == "without follow-surface":
                    effect, name = -effect, "follow-surface"
                    s, base = base, s
                if (block, s["id"], name) in seen:  # a pair found from both of its stimuli
                    continue
                seen.add((block, s["id"], name))
                effect_rows.append(
                    f"| {m['set']} | {block} | {name} | {s['id']} | {s['predicted']['jod']:.2f} | "
                    f"{base['predicted']['jod']:.2f} | {effect:+.2f} | {'yes' if abs(effect) >= 0.3 else 'no'} |"
                )
    print("| set | block | presented | conditions | best JOD | worst JOD | spread | ≥ 1 JOD |")
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(block_rows))
    print()
    print("| set | block | extension | with | JOD with | JOD without | effect | ≥ 0.3 JOD |")
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(effect_rows))


if __name__ == "__main__":
    main()
