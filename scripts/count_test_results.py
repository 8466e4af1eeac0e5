#!/usr/bin/env python3
"""Counts gtest and rostest cases in catkin's result XML and prints "N passed, N failed" last.

Exit status 1 when any case failed or errored, when a test binary left no result (catkin writes a
MISSING-RESULT failure for it) or when no case ran at all.
"""
import pathlib
import sys
import xml.etree.ElementTree as ElementTree


def main(results_directory: str) -> int:
    passed = failed = skipped = 0
    failures = []
    files = sorted(pathlib.Path(results_directory).glob("**/*.xml"))
    for path in files:
        try:
            root = ElementTree.parse(path).getroot()
        except ElementTree.ParseError as error:
            failed += 1
            failures.append(f"{path.name}: unreadable result XML ({error})")
            continue
        cases = list(root.iter("testcase"))
        # rostest writes a wrapper file (rostest-*.xml) with one case per .test launch besides
        # the gtest node's own cases (rosunit-*.xml): count the wrapper only when it failed (e.g.
        # the test node never reported), so each passing case is counted once.
        wrapper = path.name.startswith("rostest-")
        if not cases and (int(root.get("failures", 0)) or int(root.get("errors", 0))):
            failed += 1
            failures.append(f"{path.name}: {root.get('name', 'suite')} failed without test cases")
        for case in cases:
            name = f"{case.get('classname', '')}.{case.get('name', '')}"
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
                failures.append(f"{path.name}: {name}")
            elif wrapper:
                continue
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
            else:
                passed += 1
    for line in failures:
        print(f"FAILED {line}")
    if passed + failed == 0:
        print("no test case ran")
        failed = 1
    suffix = f", {skipped} skipped" if skipped else ""
    print(f"{passed} passed, {failed} failed{suffix}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
