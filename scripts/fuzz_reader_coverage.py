#!/usr/bin/env python3
"""Line coverage of the reading code of the reader files, from `llvm-cov export -format=lcov`.

The reader files also hold the writers, which the fuzz harnesses do not call, so file
totals understate what a corpus reaches. A function is writing code when its demangled
name says so (write*/Writer/append_*/...); its lines (from its first line to the next
function's) are left out. Lines are counted once however many template instances cover them.
usage: llvm-cov export -format=lcov BIN -instr-profile=P FILES | fuzz_reader_coverage.py
"""
import re
import subprocess
import sys

WRITER = re.compile(r"write|Writer|writer|\bOut\b|append_|plan_solutions|mesh_binary|mesh_ascii|"
                    r"binary_size_estimate|tet_refs_of|tag_at|Solution::size|xml_escape|put<|"
                    r"ElementSets|element_sets|emit|encode")

files = {}  # path -> {"fn": [(line, mangled)], "da": {line: hits}}
cur = None
for row in sys.stdin:
    row = row.strip()
    if row.startswith("SF:"):
        cur = files.setdefault(row[3:], {"fn": [], "da": {}})
    elif row.startswith("FN:") and cur is not None:
        line, name = row[3:].split(",", 1)
        cur["fn"].append((int(line), name))
    elif row.startswith("DA:") and cur is not None:
        line, hits = row[3:].split(",")[:2]
        cur["da"][int(line)] = max(cur["da"].get(int(line), 0), int(hits))

mangled = sorted({n for f in files.values() for _, n in f["fn"]})
demangled = subprocess.run(["c++filt"], input="\n".join(mangled), capture_output=True, text=True).stdout.split("\n")
name_of = dict(zip(mangled, demangled))

total = covered = 0
for path, f in sorted(files.items()):
    starts = sorted({(line, WRITER.search(name_of.get(n, n)) is not None) for line, n in f["fn"]})
    # A start line shared by a reading and a writing instance counts as reading.
    writing_at = {}
    for line, w in starts:
        writing_at[line] = writing_at.get(line, True) and w
    bounds = sorted(writing_at.items())
    def writing(line):
        w = False
        for start, is_w in bounds:
            if start > line:
                break
            w = is_w
        return w
    n = c = 0
    for line, hits in f["da"].items():
        if writing(line):
            continue
        n += 1
        c += hits > 0
    total += n
    covered += c
    print(f"  {path.split('/')[-1]}: reading code {c}/{n} lines ({100.0 * c / max(n, 1):.1f}%)")
print(f"  reading code in all: {covered}/{total} lines ({100.0 * covered / max(total, 1):.1f}%)")
