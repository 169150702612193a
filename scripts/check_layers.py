#!/usr/bin/env python3
"""What may include what in rt/ and core/: each folder's README.md ends with a line

    Depends on: `core/`, `core/fem/`, `rt/`

naming the folders whose headers its files may include (its own always; "nothing of the
project's" names none). Every `#include "…"` of the project's own headers in those folders is
checked against that line; a folder without the line, an include of a folder it does not name,
or an include of a header that does not exist fails the check, saying which file and line.

Usage: check_layers.py [SOURCE_DIR]   (exit 0: every include is allowed; 1: what to fix is printed)
"""
import pathlib
import re
import sys

CHECKED = ("rt", "core")  # these folders and every folder below them
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
DEPENDS = re.compile(r"^Depends on:(.*)$", re.MULTILINE)


def folder_of(path):
    """'core/fem/' for 'core/fem/hex8_element.hpp'."""
    parent = pathlib.PurePosixPath(path).parent.as_posix()
    return "" if parent == "." else parent + "/"


def allowed_folders(root, folder):
    readme = root / folder / "README.md"
    if not readme.exists():
        return None, f"{folder}README.md is missing: it must say what {folder} depends on"
    found = DEPENDS.search(readme.read_text(encoding="utf-8"))
    if not found:
        return None, f"{folder}README.md has no 'Depends on:' line"
    named = set(re.findall(r"`([^`]+)`", found.group(1)))
    return named | {folder}, None


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    problems, checked = [], 0
    folders = sorted({folder_of(p.relative_to(root).as_posix())
                      for top in CHECKED for p in (root / top).rglob("*")
                      if p.suffix in (".hpp", ".cpp", ".h") and p.is_file()})
    for folder in folders:
        allowed, problem = allowed_folders(root, folder)
        if problem:
            problems.append(problem)
            continue
        for source in sorted((root / folder).glob("*")):
            if source.suffix not in (".hpp", ".cpp", ".h"):
                continue
            for number, line in enumerate(source.read_text(encoding="utf-8").splitlines(), 1):
                match = INCLUDE.match(line)
                if not match:
                    continue
                included = match.group(1)
                where = f"{source.relative_to(root).as_posix()}:{number}"
                if not (root / included).exists():
                    if "/" in included and included.split("/")[0] in ("core", "rt", "daemon",
                                                                    "ipc", "device", "tools"):
                        problems.append(f"{where}: includes {included}, which does not exist")
                    continue  # generated (the LCM types) or a library's
                checked += 1
                if folder_of(included) not in allowed:
                    problems.append(f"{where}: includes {included}, but {folder}README.md "
                                    f"depends only on {', '.join(sorted(allowed))}")
    print(f"layers: {checked} includes in {len(folders)} folders under {', '.join(CHECKED)}")
    for p in problems:
        print("FAIL:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
