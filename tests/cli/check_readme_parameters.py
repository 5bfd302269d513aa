#!/usr/bin/env python3
"""README's input reference checked against `mupm --print-defaults`.

  check_readme_parameters.py MUPM_EXECUTABLE README.md

Every parameter that `mupm --print-defaults` prints must have a row in the tables of the
README's "## Input reference" section (tables headed `| parameter | type | default | meaning |`),
and every parameter those tables name must exist. For a parameter with a list of choices (its
validator's strings: enumerated options, the registry's output fields and initial-condition
names), every choice must appear in its README row.
Prints each missing or extra parameter with its full path (mupm->Solver->Time Step); exit 0
when they agree, 1 otherwise.

How the README names a parameter: a `### A → *name*` heading puts its table's rows in
mupm->A->NAME (the user-named sublists: --print-defaults shows their template as a sublist
named NAME); a parenthesis after the heading is a remark; a first cell `B → *name* → P, Q`
names P and Q in the sublists B->NAME of the section; `P, Q` names both P and Q.
"""
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

SECTION = "## Input reference"
ARROW = "→"


def print_defaults(mupm):
    """Full paths of the parameters `mupm --print-defaults` prints."""
    env = dict(os.environ)
    if hasattr(os, "geteuid") and os.geteuid() == 0:  # OpenMPI refuses root otherwise
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    try:
        run = subprocess.run([mupm, "--print-defaults"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, universal_newlines=True, env=env,
                             timeout=120)
    except (OSError, subprocess.TimeoutExpired) as e:
        sys.exit("FAIL: cannot run %s --print-defaults: %s" % (mupm, e))
    if run.returncode != 0:
        sys.exit("FAIL: %s --print-defaults exited with %d:\n%s"
                 % (mupm, run.returncode, run.stderr))
    out = run.stdout
    start, end = out.find("<ParameterList"), out.rfind("</ParameterList>")
    if start < 0 or end < 0:
        sys.exit("FAIL: no XML parameter list in the output of %s --print-defaults:\n%s"
                 % (mupm, out))
    try:
        root = ET.fromstring(out[start:end + len("</ParameterList>")])
    except ET.ParseError as e:
        sys.exit("FAIL: %s --print-defaults printed invalid XML: %s" % (mupm, e))
    # The choices of each validator: StringIntegralValidator <String stringValue=...>,
    # StringValidator <String value=...>, also inside an ArrayValidator.
    choices = {}
    for v in root.iter("Validator"):
        if v.get("validatorId") is None:
            continue
        names = [e.get("stringValue") or e.get("value") for e in v.iter("String")]
        if names:
            choices[v.get("validatorId")] = [n for n in names if n]
    params = []

    def walk(plist, path):
        for child in plist:  # Parameter and ParameterList; <Validators> is not an entry
            if child.tag == "Parameter":
                params.append(("->".join(path + [child.get("name")]),
                               choices.get(child.get("validatorId"), [])))
            elif child.tag == "ParameterList":
                walk(child, path + [child.get("name")])

    walk(root, [root.get("name")])
    return params


def split_path(text):
    """'Boundary Conditions → *name*' -> ['Boundary Conditions', 'NAME']."""
    parts = [p.strip() for p in text.split(ARROW)]
    return ["NAME" if re.fullmatch(r"\*[^*]+\*", p) else p for p in parts]


def readme_parameters(readme):
    """Full paths of the parameters the README's input reference tables name, with line numbers."""
    with open(readme, encoding="utf-8") as f:
        lines = f.read().split("\n")
    try:
        first = next(i for i, l in enumerate(lines) if l.strip() == SECTION)
    except StopIteration:
        sys.exit("FAIL: %s has no '%s' section" % (readme, SECTION))
    params = []
    heading = None
    table = None  # first cell of the current table's header row
    for i in range(first + 1, len(lines)):
        line = lines[i].strip()
        if line.startswith("## "):
            break
        if line.startswith("### "):
            # '### Materials (Physics = Micropolar Solid)': the parenthesis is a remark.
            heading = split_path(re.sub(r"\s*\(.*\)\s*$", "", line[4:]))
            continue
        if not line.startswith("|"):
            table = None
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        first_cell = cells[0]
        if table is None:
            table = first_cell  # the header row
            continue
        if table != "parameter" or re.fullmatch(r":?-+:?", first_cell):
            continue  # other tables; separator rows
        if heading is None:
            sys.exit("FAIL: %s:%d: a table row before any ### heading" % (readme, i + 1))
        path = split_path(first_cell)
        for name in path[-1].split(","):
            params.append(("->".join(["mupm"] + heading + path[:-1] + [name.strip()]), i + 1,
                           line))
    return params


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: check_readme_parameters.py MUPM_EXECUTABLE README.md")
    mupm, readme = sys.argv[1:]
    program = dict(print_defaults(mupm))
    documented = readme_parameters(readme)
    if not program:
        sys.exit("FAIL: %s --print-defaults printed no parameter" % mupm)
    doc_rows = {p: (line, text) for p, line, text in documented}
    missing = [p for p in program if p not in doc_rows]
    extra = [(p, line) for p, line, _ in documented if p not in program]
    # A choice counts as documented when it appears in the row as a word (not inside another).
    undocumented = [(p, c, doc_rows[p][0]) for p, cs in program.items() if p in doc_rows
                    for c in cs if not re.search(r"(?<![\w-])" + re.escape(c) + r"(?![\w-])",
                                                 doc_rows[p][1])]
    for p in missing:
        print("missing from %s: %s" % (readme, p))
    for p, line in extra:
        print("not a parameter (%s:%d): %s" % (readme, line, p))
    for p, c, line in undocumented:
        print("choice not in the README row (%s:%d): %s = %s" % (readme, line, p, c))
    if missing or extra or undocumented:
        print("FAIL: %d parameter(s) missing from the README's input reference, %d extra, "
              "%d choice(s) undocumented" % (len(missing), len(extra), len(undocumented)))
        return 1
    print("README input reference matches mupm --print-defaults: %d parameters and %d choices "
          "checked" % (len(program), sum(len(c) for c in program.values())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
