#!/usr/bin/python3
"""Counts test cases after a ctest run and prints "N passed, N failed".

A gtest or rostest ctest entry counts its test cases (from the XML it writes under
test_results/); any other ctest entry (shell tests, checks) counts as one. A ctest entry
that failed without its XML saying so (a crash, a timeout) counts one extra failure, so a
failure can never be hidden; one that ctest did not run (a shell test exiting with its
SKIP_RETURN_CODE, 77, when its data is absent) counts as skipped. Exit code: 0 only when nothing failed and ctest passed.
"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def xml_counts(path):
    """(tests, failures+errors, skipped) of a JUnit XML file, or None if unreadable."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError):
        return None
    suites = [root] if root.tag == "testsuite" else root.findall("testsuite")
    tests = failed = skipped = 0
    for suite in suites:
        for case in suite.iter("testcase"):
            tests += 1
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
    return tests, failed, skipped


def result_xml(results_dir, ctest_name):
    """The gtest/rostest XML that belongs to a catkin ctest entry, if any."""
    for kind in ("gtest", "rostest"):
        marker = "_%s_" % kind
        if marker in ctest_name:
            target = ctest_name.split(marker, 1)[1]
            if kind == "rostest":  # _ctest_<pkg>_rostest_test_ros_x.test -> rostest-test_ros_x.xml
                target = target[:-5] if target.endswith(".test") else target
            hits = glob.glob(os.path.join(results_dir, "**", "%s-%s.xml" % (kind, target)),
                             recursive=True)
            return hits[0] if hits else None
    return None


def main():
    build, ctest_rc = sys.argv[1], int(sys.argv[2])
    results_dir = os.path.join(build, "test_results")
    passed = failed = skipped = 0
    try:
        ctest_root = ET.parse(os.path.join(build, "ctest_results.xml")).getroot()
        entries = list(ctest_root.iter("testcase"))
    except (ET.ParseError, OSError):
        entries = []
    for entry in entries:
        name = entry.get("name", "")
        entry_failed = entry.get("status") == "fail" or entry.find("failure") is not None
        xml = result_xml(results_dir, name)
        counts = xml_counts(xml) if xml else None
        if counts and counts[0] > 0:
            tests, fails, skips = counts
            if entry_failed and fails == 0:
                fails = 1  # crashed or timed out after writing its XML
            passed += tests - fails - skips
            failed += fails
            skipped += skips
        elif entry.get("status") == "notrun" or entry.find("skipped") is not None:
            skipped += 1  # e.g. a shell test whose data is absent (SKIP_RETURN_CODE 77)
        else:
            failed += 1 if entry_failed else 0
            passed += 0 if entry_failed else 1
    if ctest_rc != 0 and failed == 0:
        failed = 1  # ctest failed for a reason no entry shows (e.g. nothing ran)
    if not entries and ctest_rc == 0:
        print("no tests ran")
        failed = 1
    line = "%d passed, %d failed" % (passed, failed)
    if skipped:
        line += ", %d skipped" % skipped
    print(line)
    sys.exit(0 if failed == 0 else 1)


if __name__ == "__main__":
    main()
