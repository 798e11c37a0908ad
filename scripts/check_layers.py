#!/usr/bin/env python3
"""scripts/check_layers.py — the build's parts include each other one way only, and every source
file says in its first lines what it owns. Exit 1 with the offending includes and files listed.

    python3 scripts/check_layers.py            (ctest: check_layers)

The parts, each a folder of src/ and include/phnn/, in the order data flows (a part may include
its own headers and those of the parts before it, never one after it; docs/DECISIONS.md "Layers"):

    common, systems, integrators, data, config, kernels, models, training, h5, store, report,
    sweep, apps

src/h5 (the HDF5 C API) is included by the store alone. A file's opening comment must say more
than its path: "// src/x/y.cpp — what it owns" on the first line, or further comment lines.
"""
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
ORDER = ["common", "systems", "integrators", "data", "config", "kernels", "models", "training",
         "h5", "store", "report", "sweep", "apps"]
ONLY_FROM = {"h5": {"h5", "store"}}
INCLUDE = re.compile(r'^\s*#\s*include\s+"(?:phnn/)?([a-z0-9_]+)/', re.M)
SOURCES = (".h", ".cpp", ".c")


def source_files():
    """(path relative to ROOT, its part) of every source file of src/ and include/phnn/."""
    for base in ("src", os.path.join("include", "phnn")):
        top = os.path.join(ROOT, base)
        for folder, _, files in os.walk(top):
            for name in sorted(files):
                if name.endswith(SOURCES):
                    path = os.path.join(folder, name)
                    yield os.path.relpath(path, ROOT), os.path.relpath(path, top).split(os.sep)[0]


def wrong_includes(part, text):
    """The parts `text` (a file of `part`) includes against the order."""
    if part not in ORDER:
        return []
    bad = []
    for used in INCLUDE.findall(text):
        if used not in ORDER or used == part:
            continue
        if used in ONLY_FROM and part not in ONLY_FROM[used]:
            bad.append(f"{used} (only {', '.join(sorted(ONLY_FROM[used] - {used}))} may)")
        elif ORDER.index(used) > ORDER.index(part):
            bad.append(used)
    return bad


def says_what_it_owns(text):
    """The opening comment says more than the file's path."""
    lines = text.splitlines()
    if not lines or not lines[0].startswith(("//", "/*")):
        return False
    first = lines[0].lstrip("/* ").strip()
    if re.search(r"\s[—-]\s*\S", first):
        return True
    return len(lines) > 1 and lines[1].startswith(("//", " *")) and len(lines[1].strip("/* ")) > 0


def main():
    problems = []
    for path, part in source_files():
        with open(os.path.join(ROOT, path), encoding="utf-8") as f:
            text = f.read()
        for used in wrong_includes(part, text):
            problems.append(f"{path}: a file of {part}/ includes {used}/")
        if not says_what_it_owns(text):
            problems.append(f"{path}: its first lines name only the file; say what it owns "
                            f"(\"// {path} — ...\")")
    for p in problems:
        print(p)
    print(f"check_layers: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
