"""The checks of a test script that makes several: one PASS/FAIL line each,
and the list of those that failed."""

failures = []


def check(ok, what):
    """Print 'PASS what' or 'FAIL what' as ok says; ok."""
    print("%s %s" % ("PASS" if ok else "FAIL", what), flush=True)
    if not ok:
        failures.append(what)
    return ok
