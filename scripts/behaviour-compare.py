#!/usr/bin/env python3
"""Compares two folders written by scripts/behaviour.sh (before and after a
change of structure): JSON documents field by field and CSV tables cell by
cell, numbers to an absolute-or-relative 1e-9 (floating-point reordering),
text exactly. Fields that time the run are skipped. Prints each difference
and one line "behaviour: N same, M differ"; exits 1 when anything differs.

    python3 scripts/behaviour-compare.py BEFORE AFTER [--tolerance 1e-9]
"""
import csv
import json
import math
import os
import sys

TIMING = ("seconds", "elapsed", "wall", "cpu_s", "time_s", "duration")


def close(a, b, tol):
    if isinstance(a, bool) or isinstance(b, bool):
        return a == b
    if a is None or b is None:
        return a is b
    if math.isnan(a) and math.isnan(b):
        return True
    return abs(a - b) <= tol * max(1.0, abs(a), abs(b))


def compare(a, b, path, tol, out):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if any(t in k for t in TIMING):
                continue
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'after' if k in b else 'before'}")
                continue
            compare(a[k], b[k], f"{path}.{k}", tol, out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} items before, {len(b)} after")
            return
        for i, (x, y) in enumerate(zip(a, b)):
            compare(x, y, f"{path}[{i}]", tol, out)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if not close(float(a), float(b), tol):
            out.append(f"{path}: {a!r} before, {b!r} after")
    elif a != b:
        sa, sb = str(a), str(b)
        out.append(f"{path}: {sa[:120]!r} before, {sb[:120]!r} after")


def number(x):
    try:
        return float(x)
    except ValueError:
        return None


def compare_csv(fa, fb, name, tol, out):
    with open(fa, newline="") as f:
        ra = list(csv.reader(f))
    with open(fb, newline="") as f:
        rb = list(csv.reader(f))
    if len(ra) != len(rb):
        out.append(f"{name}: {len(ra)} rows before, {len(rb)} after")
        return
    header = ra[0] if ra else []
    for i, (x, y) in enumerate(zip(ra, rb)):
        if len(x) != len(y):
            out.append(f"{name} row {i}: {len(x)} cells before, {len(y)} after")
            continue
        for j, (p, q) in enumerate(zip(x, y)):
            if p == q:
                continue
            col = header[j] if j < len(header) else j
            if any(t in str(col) for t in TIMING):
                continue
            np_, nq = number(p), number(q)
            if np_ is not None and nq is not None and close(np_, nq, tol):
                continue
            out.append(f"{name} row {i} column {col}: {p!r} before, {q!r} after")


def main():
    args = sys.argv[1:]
    tol = 1e-9
    if "--tolerance" in args:
        i = args.index("--tolerance")
        tol = float(args[i + 1])
        del args[i : i + 2]
    before, after = args
    same = differ = 0
    for name in sorted(set(os.listdir(before)) | set(os.listdir(after))):
        fa, fb = os.path.join(before, name), os.path.join(after, name)
        out = []
        if not os.path.exists(fa) or not os.path.exists(fb):
            out.append(f"only in {'after' if os.path.exists(fb) else 'before'}")
        elif name.endswith(".json"):
            ta, tb = open(fa).read(), open(fb).read()
            try:
                compare(json.loads(ta), json.loads(tb), "", tol, out)
            except json.JSONDecodeError:
                if ta != tb:
                    out.append("text differs")
        elif name.endswith(".csv"):
            compare_csv(fa, fb, name, tol, out)
        else:
            if open(fa, "rb").read() != open(fb, "rb").read():
                out.append("differs")
        if out:
            differ += 1
            print(f"{name}:")
            for line in out[:20]:
                print(f"  {line}")
            if len(out) > 20:
                print(f"  … {len(out) - 20} more")
        else:
            same += 1
    print(f"behaviour: {same} same, {differ} differ")
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
