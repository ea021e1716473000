#!/usr/bin/env python3
"""No function over 120 lines outside tests, unless a comment right above it (or on its first
lines) says why it is one job: `// one job: …`.

Counts the lines of every `fn` body in the workspace's Rust sources (not under tests/, not in
`#[cfg(test)] mod tests`, not in examples/ or benches/), from the `fn` line to its closing brace.
Exits 1 and lists them when one is longer and not explained.

Usage: scripts/check-functions.py [--list N]   (--list: print every function over N lines)
"""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIMIT = 120
FN = re.compile(r"^(\s*)(?:pub(?:\([^)]*\))?\s+)?(?:const\s+|async\s+|unsafe\s+|extern\s+\"C\"\s+)*fn\s+(\w+)")


def functions(path):
    lines = path.read_text().split("\n")
    in_tests = None
    i = 0
    while i < len(lines):
        line = lines[i]
        if re.match(r"\s*#\[cfg\(test\)\]", line):
            in_tests = len(line) - len(line.lstrip())
        m = FN.match(line)
        if m and in_tests is None:
            indent = m.group(1)
            # The body: from the first `{` after the signature to the line `<indent>}`.
            j = i
            while j < len(lines) and "{" not in lines[j] and not lines[j].rstrip().endswith(";"):
                j += 1
            if j < len(lines) and lines[j].rstrip().endswith(";") and "{" not in lines[j]:
                i = j + 1
                continue
            k = j
            if not lines[j].rstrip().endswith("}") or lines[j].strip().startswith("fn"):
                k = j + 1
                while k < len(lines) and lines[k] != indent + "}":
                    k += 1
            length = k - i + 1
            above = "\n".join(lines[max(0, i - 6):i + 3])
            yield m.group(2), i + 1, length, "one job:" in above
            i += 1
            continue
        if in_tests is not None and re.match(r"\s*mod\s+\w+\s*\{", line):
            # skip the whole test module
            depth = 0
            while i < len(lines):
                depth += lines[i].count("{") - lines[i].count("}")
                i += 1
                if depth <= 0 and "{" in "".join(lines[i - 3:i]):
                    break
            in_tests = None
            continue
        i += 1


def main():
    listing = int(sys.argv[2]) if len(sys.argv) > 2 and sys.argv[1] == "--list" else None
    files = subprocess.run(["git", "ls-files", "*.rs"], cwd=ROOT, capture_output=True, text=True,
                           check=True).stdout.split()
    bad = []
    for f in files:
        if not (ROOT / f).exists():
            continue
        parts = Path(f).parts
        if parts[0] == "tests" or "tests" in parts[1:] or "examples" in parts or "benches" in parts:
            continue
        for name, line, length, explained in functions(ROOT / f):
            if listing is not None and length > listing:
                print(f"{f}:{line}: {name}: {length} lines{' (one job)' if explained else ''}")
            if length > LIMIT and not explained:
                bad.append(f"{f}:{line}: fn {name} is {length} lines (over {LIMIT}): split it, or say why it is one job (`// one job: …`)")
    if listing is not None:
        return 0
    for b in bad:
        print(b)
    if bad:
        return 1
    print(f"no function over {LIMIT} lines outside tests")
    return 0


if __name__ == "__main__":
    sys.exit(main())
