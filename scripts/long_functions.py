#!/usr/bin/env python3
"""Lists the functions longer than a limit (default 100 lines, signature to closing brace) in
the crates a maintainer reads most: render, gpu, preview and the benchmarks' mains.

    python3 scripts/long_functions.py [--limit N] [PATH ...]

A function is found by its `fn` line and ends at the brace that closes its body (braces in
strings, chars and comments are skipped). Prints `lines  path:line  name`, longest first.
"""
import argparse
import pathlib
import re
import sys

DEFAULT_PATHS = ["crates/render/src", "crates/gpu/src", "crates/preview/src", "tools/brdf-preview/benches"]
FN = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:const\s+)?(?:async\s+)?(?:unsafe\s+)?fn\s+(\w+)")


def body_end(lines, start):
    """The index of the line whose brace closes the body opened at or after line `start`."""
    depth, opened = 0, False
    in_block_comment = False
    for i in range(start, len(lines)):
        text = lines[i]
        j = 0
        while j < len(text):
            two = text[j:j + 2]
            if in_block_comment:
                if two == "*/":
                    in_block_comment, j = False, j + 2
                    continue
                j += 1
                continue
            if two == "//":
                break
            if two == "/*":
                in_block_comment, j = True, j + 2
                continue
            c = text[j]
            if c == '"':
                j += 1
                while j < len(text) and text[j] != '"':
                    j += 2 if text[j] == "\\" else 1
            elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[j:j + 4]):
                j += text[j + 1:].index("'") + 1
            elif c == "{":
                depth, opened = depth + 1, True
            elif c == "}":
                depth -= 1
                if opened and depth == 0:
                    return i
            elif c == ";" and not opened:
                return None  # a declaration without a body
            j += 1
    return None


def functions(path):
    lines = path.read_text().splitlines()
    for i, line in enumerate(lines):
        m = FN.match(line)
        if m:
            end = body_end(lines, i)
            if end is not None:
                yield m.group(1), i + 1, end - i + 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, default=100)
    parser.add_argument("paths", nargs="*", default=DEFAULT_PATHS)
    args = parser.parse_args()
    found = []
    for root in args.paths:
        for path in sorted(pathlib.Path(root).rglob("*.rs")) if pathlib.Path(root).is_dir() else [pathlib.Path(root)]:
            for name, line, length in functions(path):
                if length > args.limit:
                    found.append((length, f"{path}:{line}", name))
    for length, where, name in sorted(found, reverse=True):
        print(f"{length:5}  {where}  {name}")
    print(f"{len(found)} functions over {args.limit} lines", file=sys.stderr)


if __name__ == "__main__":
    main()
