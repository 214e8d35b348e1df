#!/usr/bin/env python3
"""Times the compilation of each translation unit of a configured build, to see where a build's
time goes (CI builds everything twice: the release and the sanitizer build).

    tools/compile_times.py build-asan [PREFIX ...] [-j 2]

Reads BUILD/compile_commands.json (CMake writes it), compiles each unit once into a scratch object
(the build's own objects are left alone), and prints the seconds per unit, slowest first, then the
sums per top-level folder (src, app, tests, ...). PREFIX limits it to units whose path relative to
the repository starts with one of them (e.g. tests/dress src/io/gltf.cpp). A unit that several
targets compile is timed once and named with the count.
"""
import argparse
import collections
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("build", help="a configured build directory (holding compile_commands.json)")
    parser.add_argument("prefix", nargs="*", help="only units whose repository path starts with one of these")
    parser.add_argument("-j", "--jobs", type=int, default=os.cpu_count() or 1, help="units compiled at once")
    args = parser.parse_args()

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    path = os.path.join(args.build, "compile_commands.json")
    try:
        with open(path) as f:
            commands = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        print(f"compile_times: {path}: {e} (configure the build with CMake first)", file=sys.stderr)
        return 2

    counts = collections.Counter(os.path.relpath(e["file"], root) for e in commands)
    units, seen = [], set()
    for e in commands:
        rel = os.path.relpath(e["file"], root)
        if rel in seen or (args.prefix and not any(rel.startswith(p) for p in args.prefix)):
            continue
        seen.add(rel)
        units.append((rel, e))
    if not units:
        print("compile_times: no unit matches", file=sys.stderr)
        return 2

    scratch = tempfile.mkdtemp(prefix="drape_compile_times_")

    def compile_one(item):
        rel, e = item
        argv = shlex.split(e["command"]) if "command" in e else list(e["arguments"])
        out = os.path.join(scratch, rel.replace("/", "_") + ".o")
        argv[argv.index("-o") + 1] = out
        start = time.monotonic()
        done = subprocess.run(argv, cwd=e["directory"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        seconds = time.monotonic() - start
        if os.path.exists(out):
            os.remove(out)
        return rel, seconds, done.returncode

    with ThreadPoolExecutor(max(1, args.jobs)) as pool:
        results = list(pool.map(compile_one, units))
    os.rmdir(scratch)

    folders = collections.Counter()
    for rel, seconds, rc in sorted(results, key=lambda r: -r[1]):
        times = f" (compiled by {counts[rel]} targets)" if counts[rel] > 1 else ""
        failed = " FAILED" if rc else ""
        print(f"{seconds:7.1f} s  {rel}{times}{failed}")
        folders[rel.split("/")[0]] += seconds * counts[rel]
    print(f"\nper folder (seconds, counting each target's compile; {args.jobs} at once):")
    for folder, seconds in folders.most_common():
        print(f"{seconds:8.1f} s  {folder}")
    print(f"{sum(folders.values()):8.1f} s  in all")
    return 1 if any(rc for _, _, rc in results) else 0


if __name__ == "__main__":
    sys.exit(main())
