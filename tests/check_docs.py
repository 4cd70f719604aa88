#!/usr/bin/env python3
"""The Markdown files keep their Markdown: every heading has its space after the '#'s, every table's separator row is
intact, and no line carries what a C++ formatter does to prose (clang-format run on docs/*.md once turned
"# Tracing: ..." into "#Tracing : ..." and a table into one paragraph; nothing else would have noticed).
Usage: check_docs.py <repository root>. Prints each defect with its file and line; exits 1 if there is one."""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
files = sorted(root.glob("docs/*.md")) + [root / "README.md"]
defects = []
for f in files:
    fenced = False
    for n, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1):
        if line.startswith("```"):
            fenced = not fenced
        if fenced:
            continue
        where = f"{f.relative_to(root)}:{n}"
        if re.match(r"#+[^#\s]", line):
            defects.append(f"{where}: a heading without a space after its '#': {line[:60]}")
        if re.search(r"\| -- - \|", line):
            defects.append(f"{where}: a table's separator row broken into '-- -': {line[:60]}")
        if re.match(r"\S.* \| \| ", line) and "|" not in line[:1]:
            defects.append(f"{where}: table rows joined into one line: {line[:60]}")
for d in defects:
    print(d)
print(f"check_docs: {len(files)} files, {len(defects)} defects")
sys.exit(1 if defects else 0)
