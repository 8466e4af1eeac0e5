#!/usr/bin/env python3
"""Counts gtest and rostest cases in catkin's result XML against the expected-results manifest and
prints "N passed, N failed" last.

Usage: count_test_results.py RESULTS_DIR [--manifest FILE] [--sources REPO]
       count_test_results.py RESULTS_DIR --write-manifest FILE   (after a full, passing run)

The manifest (test/expected_results.txt) lists every result file a full run must leave, one per
line as "<file name> <minimum number of test cases>". A run fails (exit status 1) when
  - any case failed or errored, or a result file is unreadable or failed without cases;
  - any case was skipped (GTEST_SKIP, DISABLED_ tests that were forced to run, notrun):
    a skipped case counts as a failure, not as a pass;
  - a listed result file is missing (the binary was never built, registered or run) or holds
    fewer cases than listed (an empty result, a suite that lost its cases);
  - a result file is not listed (a new test: add it to the manifest);
  - with --sources, a test source (test/unit/*.cpp, test/ros_unit/*.cpp, test/integration/*.test,
    test/python/test_*.py) has no line in the manifest (a test that would never be expected);
  - no case ran at all.
"""
import argparse
import pathlib
import sys
import xml.etree.ElementTree as ElementTree

# Header-only helpers in test/unit that CMake does not turn into a test.
NOT_TESTS = {"test_utilities"}


def read_manifest(path: pathlib.Path):
    expected = {}
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.split()
        if len(parts) != 2 or not parts[1].isdigit():
            raise ValueError(f"{path}:{number}: expected '<result file> <minimum cases>', got '{line}'")
        expected[parts[0]] = int(parts[1])
    return expected


def expected_from_sources(repo: pathlib.Path):
    """The result file each test source makes (CMakeLists.txt: one gtest per .cpp, one rostest per .test,
    one pytest run per test/python/test_*.py)."""
    names = []
    for directory in ("test/unit", "test/ros_unit"):
        for source in sorted((repo / directory).glob("*.cpp")):
            if source.stem not in NOT_TESTS:
                names.append((f"gtest-{source.stem}.xml", source))
    for launch in sorted((repo / "test/integration").glob("*.test")):
        names.append((f"rostest-test_integration_{launch.stem}.xml", launch))
    for module in sorted((repo / "test/python").glob("test_*.py")):
        # the study runner's modules run as one pytest, the others one result file each
        names.append(("pytest-study_units.xml" if module.stem.startswith("test_study_") else f"pytest-{module.stem}.xml",
                      module))
    return names


def write_manifest(results: pathlib.Path, manifest: pathlib.Path) -> int:
    lines = ["# Every result file a full run of scripts/run_tests.sh must leave, with its minimum number of",
             "# test cases (checks/count_test_results.py). A missing file, fewer cases, a skipped case or an",
             "# unlisted file fails the run. Regenerate after adding tests, from a full passing run:",
             "#   /usr/bin/python3 checks/count_test_results.py .ws/build/test_results/birkhoff_cart \\",
             "#       --write-manifest test/expected_results.txt"]
    for path in sorted(results.glob("**/*.xml")):
        cases = len(list(ElementTree.parse(path).getroot().iter("testcase")))
        lines.append(f"{path.name} {cases}")
    manifest.write_text("\n".join(lines) + "\n")
    print(f"wrote {manifest} ({len(lines) - 5} result files)")
    return 0


def main(argv) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="catkin's test_results/<package> directory")
    parser.add_argument("--manifest", type=pathlib.Path, help="expected result files and case counts")
    parser.add_argument("--sources", type=pathlib.Path, help="repository whose test sources the manifest must list")
    parser.add_argument("--write-manifest", type=pathlib.Path,
                        help="write the result files and case counts of RESULTS_DIR as a manifest, then exit")
    arguments = parser.parse_args(argv)
    if arguments.write_manifest is not None:
        return write_manifest(pathlib.Path(arguments.results), arguments.write_manifest)

    passed = failed = 0
    failures = []
    cases_per_file = {}
    files = sorted(pathlib.Path(arguments.results).glob("**/*.xml"))
    for path in files:
        try:
            root = ElementTree.parse(path).getroot()
        except ElementTree.ParseError as error:
            failed += 1
            failures.append(f"{path.name}: unreadable result XML ({error})")
            continue
        cases = list(root.iter("testcase"))
        cases_per_file[path.name] = len(cases)
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
            elif case.find("skipped") is not None or case.get("status") == "notrun" or case.get("result") == "skipped":
                failed += 1
                failures.append(f"{path.name}: {name} was SKIPPED (a skipped case is not a pass)")
            elif not wrapper:
                passed += 1

    if arguments.manifest is not None:
        try:
            expected = read_manifest(arguments.manifest)
        except (OSError, ValueError) as error:
            print(f"FAILED manifest: {error}")
            print(f"{passed} passed, {failed + 1} failed")
            return 1
        for name, minimum in sorted(expected.items()):
            if name not in cases_per_file:
                failed += 1
                failures.append(f"{name}: MISSING (listed in {arguments.manifest.name}; never built, registered or run)")
            elif cases_per_file[name] < minimum:
                failed += 1
                what = "EMPTY" if cases_per_file[name] == 0 else "TOO FEW CASES"
                failures.append(f"{name}: {what} ({cases_per_file[name]} cases, at least {minimum} expected)")
        for name in sorted(set(cases_per_file) - set(expected)):
            failed += 1
            failures.append(f"{name}: UNLISTED result (add '{name} {cases_per_file[name]}' to {arguments.manifest.name})")
        if arguments.sources is not None:
            for name, source in expected_from_sources(arguments.sources):
                if name not in expected:
                    failed += 1
                    failures.append(f"{name}: the test source {source.relative_to(arguments.sources)} is not in "
                                    f"{arguments.manifest.name}")

    for line in failures:
        print(f"FAILED {line}")
    if passed + failed == 0:
        print("no test case ran")
        failed = 1
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
