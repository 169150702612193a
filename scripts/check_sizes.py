#!/usr/bin/env python3
"""The size bound on hapticsim's own code: no function over 80 lines and no file over 500 in
core/, rt/, daemon/, ipc/ and device/ (tests and generated code are exempt).

Functions are measured with Universal Ctags (first to last line, comments and blank lines
included; a lambda counts as part of the function it is written in), named with their class and
namespace (anonymous namespaces left out). What was over the bound
when the bound came is listed in scripts/size-bounds.txt, each at its size then: it may not grow,
and its entry is lowered as it shrinks and removed once it is within the bound. Anything else
over the bound fails the check.

Usage: check_sizes.py [SOURCE_DIR]   (exit 0: within the bounds; 1: what to fix is printed)
"""
import collections
import pathlib
import subprocess
import sys

FUNCTION_LINES, FILE_LINES = 80, 500
FOLDERS = ("core", "rt", "daemon", "ipc", "device")


def ctags_program():
    """Universal Ctags under either of its names (Exuberant Ctags lacks --_xformat)."""
    for name in ("ctags-universal", "universal-ctags", "ctags"):
        try:
            version = subprocess.run([name, "--version"], capture_output=True, text=True).stdout
        except FileNotFoundError:
            continue
        if "Universal Ctags" in version:
            return name
    sys.exit("check_sizes: Universal Ctags is not installed (scripts/setup.sh installs "
             "universal-ctags)")


def measure(root):
    files = sorted(p for folder in FOLDERS for p in (root / folder).rglob("*")
                   if p.suffix in (".cpp", ".hpp", ".h", ".cc") and p.is_file()
                   and not any(part.startswith(".") for part in p.relative_to(root).parts))
    sizes = {}
    for path in files:
        with open(path, encoding="utf-8") as f:
            sizes[("file", path.relative_to(root).as_posix(), "")] = sum(1 for _ in f)
    out = subprocess.run(
        [ctags_program(), "--languages=C++", "--kinds-C++=f", "--fields=+neZ", "-x",
         "--_xformat=%{line} %{end} %F %{scope} %N"]
        + [str(p.relative_to(root)) for p in files],
        cwd=root, check=True, capture_output=True, text=True).stdout
    definitions = collections.defaultdict(list)
    for line in out.splitlines():
        first, last, path, scope, name = line.split(" ", 4)
        if name.startswith("__anon"):
            continue  # a lambda: measured with the function around it
        if last == "-":
            print(f"check_sizes: no end line for {path}: {name}() (not measured)")
            continue
        # Anonymous namespaces' names change with the file: left out of the function's name.
        qualified = "::".join(part for part in scope.split("::")
                              if part and part != "-" and not part.startswith("__anon"))
        key = ("function", path, f"{qualified}::{name}" if qualified else name)
        definitions[key].append(int(last) - int(first) + 1)
    overloads = []  # functions of one name with more than one definition over the bound
    for key, lines in definitions.items():
        sizes[key] = max(lines)
        if sum(n > FUNCTION_LINES for n in lines) > 1:
            overloads.append(key)
    return sizes, overloads


def bounds(path):
    listed = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        kind, lines, where, *name = line.split()
        listed[(kind, where, name[0] if name else "")] = int(lines)
    return listed


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    (sizes, overloads), listed = measure(root), bounds(root / "scripts" / "size-bounds.txt")
    problems = [f"{where}: {name}() has more than one definition over the bound of "
                f"{FUNCTION_LINES} lines: split them" for _, where, name in overloads]
    for (kind, where, name), lines in sorted(sizes.items()):
        limit = FUNCTION_LINES if kind == "function" else FILE_LINES
        what = f"{where}: {name}()" if name else where
        allowed = listed.get((kind, where, name))
        if lines <= limit:
            if allowed is not None:
                problems.append(f"{what} is {lines} lines, within the bound of {limit}: remove "
                                f"its entry from scripts/size-bounds.txt")
        elif allowed is None:
            problems.append(f"{what} is {lines} lines, over the bound of {limit} for a {kind}: "
                            f"split it")
        elif lines > allowed:
            problems.append(f"{what} grew to {lines} lines (it was {allowed}, over the bound of "
                            f"{limit}): it may only shrink")
        elif lines < allowed:
            problems.append(f"{what} shrank to {lines} lines: lower its entry in "
                            f"scripts/size-bounds.txt from {allowed} to {lines}")
    for key in listed:
        if key not in sizes:
            problems.append(f"scripts/size-bounds.txt lists {key[1]} {key[2]}, which no longer "
                            f"exists: remove the entry")
    over = collections.Counter(k for (k, _, _), n in sizes.items()
                               if n > (FUNCTION_LINES if k == "function" else FILE_LINES))
    largest = {k: max(((n, w, f) for (kk, w, f), n in sizes.items() if kk == k), default=None)
               for k in ("function", "file")}
    print(f"sizes: {len(sizes)} files and functions in {', '.join(FOLDERS)}; over the bound: "
          f"{over['function']} functions (> {FUNCTION_LINES} lines), {over['file']} files "
          f"(> {FILE_LINES}); largest function {largest['function'][1]}: "
          f"{largest['function'][2]}() {largest['function'][0]} lines, largest file "
          f"{largest['file'][1]} {largest['file'][0]} lines")
    for problem in problems:
        print("FAIL:", problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
