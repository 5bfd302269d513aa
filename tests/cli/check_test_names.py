#!/usr/bin/env python3
"""The GoogleTest files follow tests/CMakeLists.txt's naming convention, and every test runs.

  check_test_names.py MUPM_TESTS TESTS_DIR SOURCE...

For each SOURCE (tests/<layer>/test_<name>.cpp): every suite it defines is named <Name> or
<Name><Qualifier>, <Name> the CamelCase of <name> (test_j_integral.cpp: JIntegral,
JIntegralKField, JIntegralSentLong), and no suite is defined in two files. Then every test that
`MUPM_TESTS --gtest_list_tests` lists belongs to a suite read from one SOURCE, the way
tests/CMakeLists.txt reads them to make its ctest entries (a test outside them would never run).
Prints each violation; exit 0 when there is none, 1 otherwise.
"""
import fnmatch
import os
import re
import subprocess
import sys

# The same pattern as tests/CMakeLists.txt.
DEFINITION = re.compile(r"(TYPED_TEST|TEST_P|TEST_F|TEST)\(([A-Za-z0-9]+),")


def camel(name):
    return "".join(part[:1].upper() + part[1:] for part in name.split("_"))


def patterns(kind, suite):
    """The gtest filter pattern that selects a suite's tests (as tests/CMakeLists.txt)."""
    if kind == "TYPED_TEST":
        return suite + "/*"
    if kind == "TEST_P":
        return "*/" + suite + ".*"
    return suite + ".*"


def main():
    binary, tests_dir, sources = sys.argv[1], sys.argv[2], sys.argv[3:]
    errors = []
    owner = {}  # suite -> source
    selectors = []  # (pattern, source)
    for source in sources:
        name = re.sub(r"^test_", "", os.path.splitext(os.path.basename(source))[0])
        with open(os.path.join(tests_dir, source)) as f:
            found = DEFINITION.findall(f.read())
        if not found:
            errors.append(f"{source}: defines no test")
        for kind, suite in found:
            if not suite.startswith(camel(name)):
                errors.append(f"{source}: suite {suite} is not named after its file "
                              f"({camel(name)} or {camel(name)}<Qualifier>)")
            if owner.setdefault(suite, source) != source:
                errors.append(f"suite {suite} defined in {owner[suite]} and {source}")
            selectors.append((patterns(kind, suite), source))
    listing = subprocess.run([binary, "--gtest_list_tests"], capture_output=True, text=True,
                             check=True).stdout
    # "Suite." or "Prefix/Suite." or "Suite/0." (then "  # TypeParam = ..."), then "  Test" or
    # "  Test/0" lines; anything else (a library's warning on stdout) is not the listing.
    suite_line = re.compile(r"^([A-Za-z0-9_]+(?:/[A-Za-z0-9_]+)*\.)(?:\s+#.*)?$")
    test_line = re.compile(r"^  ([A-Za-z0-9_]+(?:/[A-Za-z0-9_]+)*)(?:\s+#.*)?$")
    suite, count = None, 0
    for line in listing.splitlines():
        if suite_line.match(line):
            suite = suite_line.match(line).group(1)
            continue
        if not test_line.match(line) or suite is None:
            continue
        test = suite + test_line.match(line).group(1)
        count += 1
        where = {src for pattern, src in selectors if fnmatch.fnmatchcase(test, pattern)}
        if len(where) != 1:
            errors.append(f"test {test} is selected by {len(where)} files' entries "
                          f"({', '.join(sorted(where)) or 'none'}): it must be by exactly one")
    if count == 0:
        errors.append(f"{binary} --gtest_list_tests listed no test")
    for e in errors:
        print(e)
    if not errors:
        print(f"test names: {count} tests in {len(owner)} suites of {len(sources)} files, "
              f"each named after its file and in one entry")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
