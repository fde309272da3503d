"""The summary `make test` ends with: what each suite ran, on which Blender versions, how
many tests were skipped and why, and each suite's 20 slowest tests (a test over 30 s
carries a slow mark that says why; the list names any that does not). Reads the logs
scripts/test-all.sh wrote.

    python3 scripts/test_summary.py LOG_DIR SUITE...

Exits 1 when a suite failed or left no result, or when a comparison against Cycles was
skipped (those are the tests that catch a biased image; skipping one hides a failure).
"""
import os
import re
import sys


def read(path):
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            return f.read()
    except OSError:
        return None


def exit_code(text):
    m = re.findall(r"^EXIT (\d+) (\d+)$", text, re.M)
    return (int(m[-1][0]), int(m[-1][1])) if m else (None, 0)


def ctest(text):
    m = re.findall(r"(\d+)% tests passed, (\d+) tests? failed out of (\d+)", text)
    if not m:
        return None
    failed, total = int(m[-1][1]), int(m[-1][2])
    skipped = re.findall(r"^\s*\d+ - (\S+).*\(Skipped\)", text, re.M)
    return dict(ran=total - len(skipped), failed=failed,
                skipped=[(s, "ctest skip") for s in skipped],
                what=f"ctest: {total - failed - len(skipped)} passed, {failed} failed")


def pytest(text):
    m = re.findall(r"^=*\s*((?:\d+ \w+(?:, )?)+) in [\d.]+s", text, re.M)
    if not m:
        return None
    counts = {k: int(v) for v, k in re.findall(r"(\d+) (\w+)", m[-1])}
    failed = counts.get("failed", 0) + counts.get("error", 0) + counts.get("errors", 0)
    skipped = [(name, reason) for name, reason in
               re.findall(r"^SKIPPED \[\d+\] (\S+): (.*)$", text, re.M)]
    passed = counts.get("passed", 0)
    return dict(ran=passed + failed, failed=failed, skipped=skipped,
                what=f"pytest: {passed} passed, {failed} failed")


def bench(text):
    m = re.findall(r"^test-bench: [\d.]+ s, (\d+) failures?", text, re.M)
    if not m:
        return None
    runs = len(re.findall(r"^\S+: [\d.]+ s\s+\(", text, re.M))
    failed = int(m[-1])
    skipped = [(line, "bench") for line in re.findall(r"^(\S+: skipped.*)$", text, re.M)]
    return dict(ran=runs, failed=failed, skipped=skipped,
                what=f"glslppm-bench: {runs} runs checked, {failed} failures")


def blender(text):
    # tests/blender/run.py's "RESULT Blender 3.4.1: ..." and the viewport suite's
    # "RESULT Blender 3.4.1 (viewport): ...", and the user path suite's runs.
    results = re.findall(r"^RESULT Blender ([\d.]+)(?: \((?:viewport|user path)\))?: (\d+) passed, "
                         r"(\d+) failed, (\d+) skipped", text, re.M)
    if not results:
        return None
    skipped = re.findall(r"^SKIP (\S+): (.*)$", text, re.M)
    versions = [v for v, *_ in results]
    passed = sum(int(p) for _, p, _, _ in results)
    failed = sum(int(f) for _, _, f, _ in results)
    per = "; ".join(f"Blender {v}: {p} passed, {f} failed" for v, p, f, _ in results)
    return dict(ran=passed + failed, failed=failed, skipped=skipped, versions=versions,
                what=per)


def extension(text):
    # scripts/test-extension.sh's "RESULT extension: N passed, M failed (K KiB zip)".
    m = re.findall(r"^RESULT extension: (\d+) passed, (\d+) failed(.*)$", text, re.M)
    if not m:
        return None
    passed, failed, rest = int(m[-1][0]), int(m[-1][1]), m[-1][2].strip()
    return dict(ran=passed + failed, failed=failed, skipped=[],
                what=f"extension zip: {passed} passed, {failed} failed {rest}".strip())


def fuzz(text):
    replays = re.findall(r"^fuzz (\S+): (\d+) kept inputs replayed, no crash", text, re.M)
    failed = len(re.findall(r"^fuzz \S+: FAILED", text, re.M))
    if not replays and not failed:
        return None
    inputs = sum(int(n) for _, n in replays)
    return dict(ran=inputs, failed=failed, skipped=[],
                what=f"{len(replays)} fuzz targets, {inputs} kept inputs replayed, "
                     f"{failed} crashed")


SLOWEST_SHOWN = 20
SLOW_SECONDS = 30.0


def durations(text):
    """[(seconds, name, note)] of one suite's log, slowest first: the DURATION lines of the
    pytest and Blender runners (tests/python/conftest.py, tests/blender/run.py), else
    ctest's "Test #N: name .... Passed 1.23 sec", the bench's "name: 1.2 s (command)" and
    the UI suites' "PASS name (1.2 s)" (their label in brackets). Slow marks are the pytest
    and Blender tests' (their runners flag a test over 30 s without one); a UI suite's step
    is one stage of a session in Blender's window, a GoogleTest is timed by ctest alone."""
    found = [(float(s), name, note.strip()) for s, name, note in
             re.findall(r"^DURATION ([\d.]+) (\S+(?: \[Blender [\d.]+\])?)(.*)$", text, re.M)]
    if not found:
        found = [(float(s), name, "") for name, s in
                 re.findall(r"^\s*\d+/\d+ Test\s+#\d+: (\S+) \.+\s*\**\w+\s+([\d.]+) sec",
                            text, re.M)]
        found += [(float(s), f"{name} ({command})", "") for name, s, command in
                  re.findall(r"^(\S+): ([\d.]+) s\s+\((.*)\)$", text, re.M)]
        found += [(float(s), f"{name} {label or ''}".strip(), "") for label, name, s in
                  re.findall(r"^(\[[^\]]+\] )?(?:PASS|FAIL) (\S+) \(([\d.]+) s\)", text, re.M)]
    return sorted(found, key=lambda item: -item[0])


def print_slowest(log_dir, suites):
    unmarked = 0
    for suite in suites:
        found = durations(read(os.path.join(log_dir, f"{suite}.log")) or "")
        unmarked += sum("NOT MARKED SLOW" in note for _, _, note in found)
        if not found:
            continue
        print(f"-- {suite}: the {min(len(found), SLOWEST_SHOWN)} slowest of {len(found)} --")
        for seconds, name, note in found[:SLOWEST_SHOWN]:
            print(f"  {seconds:7.1f} s  {name} {note}".rstrip())
    if unmarked:
        print(f"{unmarked} tests took over {SLOW_SECONDS:.0f} s without a slow mark saying why")


PARSERS = {"native": ctest, "python": pytest, "bench": bench, "blender": blender,
           "viewport": blender, "user-path": blender, "extension": extension, "sanitize": ctest,
           "fuzz-replay": fuzz}


def main():
    log_dir, suites = sys.argv[1], sys.argv[2:]
    ok = True
    total = 0
    skipped = []
    versions = []
    print("== slowest tests ==")
    print_slowest(log_dir, suites)
    print("== test summary ==")
    for suite in suites:
        text = read(os.path.join(log_dir, f"{suite}.log"))
        rc, seconds = exit_code(text or "")
        result = PARSERS[suite](text) if text else None
        if result is None:
            print(f"{suite:12s} NO RESULT (exit {rc}; see {log_dir}/{suite}.log)")
            ok = False
            continue
        state = "ok" if rc == 0 and result["failed"] == 0 else "FAILED"
        ok &= state == "ok"
        total += result["ran"]
        skipped += [(suite, name, reason) for name, reason in result["skipped"]]
        # The user path suite names Blenders by the matrix's labels (3.4): the other suites
        # have already named them in full (3.4.1).
        if suite != "user-path":
            versions += [v for v in result.get("versions", []) if v not in versions]
        print(f"{suite:12s} {state:6s} {result['what']} ({seconds} s)")
    for suite, name, reason in skipped:
        print(f"skipped in {suite}: {name}: {reason}")
    cycles_skipped = [name for _, name, _ in skipped if "cycles" in name.lower()]
    if cycles_skipped:
        print(f"FAILED: {len(cycles_skipped)} comparisons against Cycles were skipped")
        ok = False
    blender = (f"Blender {', '.join(versions[:-1])} and {versions[-1]}" if len(versions) > 1
               else f"Blender {versions[0]}" if versions else "no Blender")
    print(f"{'TESTS PASSED' if ok else 'TESTS FAILED'}: {total} tests in {len(suites)} suites, "
          f"{blender}, {len(skipped)} skipped")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
