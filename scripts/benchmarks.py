#!/usr/bin/env python3
"""Runs the project's benchmarks and writes their reports into docs/benchmarks.md.

    python3 scripts/benchmarks.py             every benchmark, in the order below (make bench)
    python3 scripts/benchmarks.py NAME...     those only; the other sections stay as they are
    python3 scripts/benchmarks.py --list      the names

Each benchmark prints its report on stdout (shown as it runs; its progress goes to stderr). When
it exits 0, its section of docs/benchmarks.md is replaced by that report, stamped with the commit
(and whether the tree had uncommitted changes), the date and the machine it ran on. A benchmark
that fails leaves its section as it was, the others still run, and the exit status is 1.
"""

import datetime
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "benchmarks.md"

# (name, title, command, what its report is: "text" is shown as printed, "markdown" as written)
BENCHMARKS = [
    ("importance", "Importance tables of one material", "cargo bench -p importance --bench build", "text"),
    ("envmap", "Loading the real maps and their mip chains", "cargo bench -p envmap --bench load", "text"),
    (
        "bandwidth",
        "The D4 transform against PyWavelets; the environment's bandwidth",
        "cargo bench -p bandwidth --bench bandwidth",
        "text",
    ),
    ("prefilter", "The prefilter against the brute-force convolution", "cargo bench -p prefilter --bench prefilter", "text"),
    ("atlas", "The bandwidth atlas of one material", "cargo bench -p bandwidth-atlas --bench atlas", "text"),
    ("stages", "The stages of one bake", "cargo bench -p bake --bench stages", "text"),
    (
        "table1",
        "The wavelet BRDF's errors (Claustres et al. 2007, Table 1) on the 20 real-derived materials",
        "cargo bench -p wavelet-brdf --bench table1",
        "markdown",
    ),
    (
        "adaptive",
        "Adaptive shading against the brute force at equal quality, on the GPU",
        "cargo bench -p brdf-preview --bench adaptive -- --gpu",
        "markdown",
    ),
    ("mitsuba", "The CPU renderer against Mitsuba 3", "cargo bench -p brdf-preview --bench mitsuba", "markdown"),
    (
        "fits",
        "brdf-fit's glTF materials against the 20 measured tables, in pictures",
        "cargo bench -p brdf-preview --bench fits",
        "markdown",
    ),
    ("frontier", "The three.js material against three.js's own", "node engines/three/bench/frontier.mjs", "markdown"),
    ("gltf", "brdf-fit's glTF materials in three.js", "node engines/three/bench/gltf.mjs", "markdown"),
]

HEADER = """# Benchmarks

Written by `make bench` (`python3 scripts/benchmarks.py NAME...` reruns some and keeps the rest;
do not edit by hand). Each section is one benchmark's report as it printed it, stamped with the
commit, date and machine of its run; what a benchmark measures, and how, is in the doc comment
of its source. The machines are shared and noisy: each benchmark times its baseline in the same
run, and the ratios to it are the figures to compare between runs.
"""


def run(args):
    return subprocess.run(args, cwd=ROOT, capture_output=True, text=True).stdout.strip()


def stamp():
    commit = run(["git", "rev-parse", "--short=12", "HEAD"]) or "unknown"
    # The report itself changes as the sections of one run are written: it does not count.
    if run(["git", "status", "--porcelain", "--untracked-files=no", "--", ".", ":!docs/benchmarks.md"]):
        commit += " with uncommitted changes"
    cpu = "unknown CPU"
    try:
        models = re.findall(r"^model name\s*:\s*(.+)$", Path("/proc/cpuinfo").read_text(), re.M)
        if models:
            cpu = models[0].strip()
    except OSError:
        pass
    try:
        kib = int(re.search(r"^MemTotal:\s*(\d+)", Path("/proc/meminfo").read_text(), re.M).group(1))
        memory = f", {kib / 2**20:.0f} GiB"
    except (OSError, AttributeError):
        memory = ""
    load = f", load {os.getloadavg()[0]:.1f} at the start" if hasattr(os, "getloadavg") else ""
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    return f"commit {commit}, {date}, {os.cpu_count()} logical CPUs ({cpu}{memory}){load}"


def section(name, title, command, when, body=None):
    """A section of the document: its markers, title, command and stamp, then `body`, if any."""
    body = f"\n{body}" if body is not None else ""
    return f"<!-- benchmark: {name} -->\n## {title}\n\n`{command}`: {when}.\n{body}\n<!-- end: {name} -->\n"


def report_body(kind, report):
    """A report as a section shows it: text as printed; markdown with its headings below the
    section's (its `#` is the section's `##` plus one)."""
    if kind == "markdown":
        return re.sub(r"^#", "###", report.rstrip(), flags=re.M)
    return "```text\n" + report.rstrip() + "\n```"


def sections(text):
    """The sections of the document, by name."""
    found = {}
    for m in re.finditer(r"<!-- benchmark: (\S+) -->\n.*?<!-- end: \1 -->\n", text, re.S):
        found[m.group(1)] = m.group(0)
    return found


def write(found):
    """docs/benchmarks.md: the header, then the sections in the order of BENCHMARKS."""
    parts = [HEADER]
    for name, title, command, _ in BENCHMARKS:
        parts.append(found.get(name) or section(name, title, command, "not run yet"))
    DOC.parent.mkdir(exist_ok=True)
    tmp = DOC.with_suffix(".md.tmp")
    tmp.write_text("\n".join(parts))
    tmp.replace(DOC)


def main(argv):
    names = [name for name, *_ in BENCHMARKS]
    if argv == ["--list"]:
        print("\n".join(names))
        return 0
    unknown = [a for a in argv if a not in names]
    if unknown:
        print(f"error: no benchmark named {', '.join(unknown)} (the names: {', '.join(names)})", file=sys.stderr)
        return 2
    failed = []
    for name, title, command, kind in BENCHMARKS:
        if argv and name not in argv:
            continue
        when = stamp()
        print(f"==> {name}: {command}", file=sys.stderr, flush=True)
        process = subprocess.Popen(command, shell=True, cwd=ROOT, stdout=subprocess.PIPE, text=True)
        lines = []
        for line in process.stdout:
            sys.stdout.write(line)
            sys.stdout.flush()
            lines.append(line)
        if process.wait() != 0:
            print(f"error: {command} exited with status {process.returncode}; its section is unchanged", file=sys.stderr)
            failed.append(name)
            continue
        found = sections(DOC.read_text()) if DOC.exists() else {}
        found[name] = section(name, title, command, when, report_body(kind, "".join(lines)))
        write(found)
        print(f"==> {name}: its report is in {DOC.relative_to(ROOT)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
