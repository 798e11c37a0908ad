#!/usr/bin/env python3
"""Lists C++ functions over 80 lines and source files over 400 lines (a warning, not an error).

    python3 scripts/check_sizes.py            # from anywhere; exit status 0
    python3 scripts/check_sizes.py --strict   # exit status 1 if anything is listed

A file may be long for a reason: a comment line starting with "// Size:" in its first 15 lines
states that reason, and the file is then not listed. Functions are found heuristically: a
definition starts at column 0 (the house style does not indent namespace contents), its body
ends at the next "}" at column 0, and lambdas count toward the function that holds them.
Functions defined inside a class body are not measured.
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DIRS = ["src", "include", "bench", "tests"]
MAX_FUNCTION, MAX_FILE = 80, 400
START = re.compile(r"^[A-Za-z_][\w:<>,*&\s\[\]]*\b[\w:~]+\s*\(")
SKIP = re.compile(r"^(namespace|class|struct|enum|union|template\s*<[^>]*>\s*(class|struct)|"
                  r"using|typedef|#|//|extern\s+\"C\"\s*\{)")


def functions(lines):
    """(name, first line, length) of each column-0 function definition."""
    out, i = [], 0
    while i < len(lines):
        line = lines[i]
        if START.match(line) and not SKIP.match(line) and not line.rstrip().endswith(";"):
            j = i
            while j < len(lines) and "{" not in lines[j] and not lines[j].rstrip().endswith(";"):
                j += 1
            if j < len(lines) and "{" in lines[j]:
                k = j
                while k < len(lines) and not (lines[k].startswith("}") and k > j or
                                              (k == j and lines[k].rstrip().endswith("}"))):
                    k += 1
                name = re.findall(r"([\w:~]+)\s*\(", line)
                out.append((name[0] if name else "?", i + 1, k - i + 1))
                i = k + 1
                continue
        i += 1
    return out


def main():
    strict = "--strict" in sys.argv[1:]
    listed = 0
    for top in DIRS:
        for base, _, files in os.walk(os.path.join(ROOT, top)):
            for name in sorted(files):
                if not name.endswith((".cpp", ".h")):
                    continue
                path = os.path.join(base, name)
                rel = os.path.relpath(path, ROOT)
                with open(path, encoding="utf-8") as f:
                    lines = f.read().split("\n")
                reason = any(l.startswith("// Size:") for l in lines[:15])
                if len(lines) > MAX_FILE and not reason:
                    print(f"warning: {rel}: {len(lines)} lines (> {MAX_FILE}) and no "
                          f"'// Size:' reason in its first lines")
                    listed += 1
                for fn, first, length in functions(lines):
                    if length > MAX_FUNCTION:
                        print(f"warning: {rel}:{first}: {fn} is {length} lines (> {MAX_FUNCTION})")
                        listed += 1
    print(f"check_sizes: {listed} item(s) listed")
    return 1 if strict and listed else 0


if __name__ == "__main__":
    sys.exit(main())
