#!/usr/bin/env python3
"""Source files over the line limit (the developers' guide: no file over 600
lines; `make lint` runs this). Checks every file git tracks with a code
extension (Rust, GLSL, Python, shell); prints each one over the limit with
its length and exits 1 if there is any. Usage, from the repository root:
`python3 tools/line_limit.py [LIMIT]` (default 600).
"""
import subprocess
import sys

EXTENSIONS = (".rs", ".glsl", ".comp", ".frag", ".vert", ".py", ".sh")


def main():
    limit = int(sys.argv[1]) if len(sys.argv) > 1 else 600
    files = subprocess.run(
        ["git", "ls-files", "-z"], check=True, capture_output=True, text=True
    ).stdout.split("\0")
    over = []
    for path in files:
        if not path.endswith(EXTENSIONS):
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = sum(1 for _ in f)
        if lines > limit:
            over.append((lines, path))
    for lines, path in sorted(over, reverse=True):
        print(f"{path}: {lines} lines, over the {limit}-line limit")
    print(f"line limit: {len(over)} file(s) over {limit} lines")
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
