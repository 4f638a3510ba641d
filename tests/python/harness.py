"""The tiny check runner the read-back scripts share: run each check, print
PASS/FAIL with the traceback, and close with "python: N passed, M failed"
(a line the CI reads)."""

import sys
import traceback

_results = []


def run_check(label, fn, *args):
    """Runs fn(*args); a raised exception is a failure, reported and survived."""
    try:
        fn(*args)
        _results.append(True)
        print(f"PASS {label}")
    except Exception:  # noqa: BLE001 - report every failure and go on
        _results.append(False)
        print(f"FAIL {label}")
        traceback.print_exc(file=sys.stdout)


def finish():
    """Prints the closing line; returns the exit code (1 on any failure)."""
    passed = sum(_results)
    failed = len(_results) - passed
    print(f"python: {passed} passed, {failed} failed")
    return 1 if failed else 0
