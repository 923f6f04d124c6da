#!/usr/bin/python3
"""No two C and C++ files of tests/ share a file name.

  test_file_names.py --tests tests

The tests mirror the rooms (tests/README.md): a room's tests are in the folder named for it,
and a file's name says what it tests, so a name found twice (tests/sim/commands_test.cpp and
a codec test of the same name) sends a reader, a compiler message or a stack trace to the
wrong file. Folders named node_modules (npm's, not ours) are not looked in.

Exit status: 0 every name once (one summary line), 1 a name found twice or more (one line a
name, with each path), 2 bad usage or a folder that cannot be read.
"""
import argparse
import os
import pathlib
import sys

SUFFIXES = {".c", ".cc", ".cpp", ".h", ".hpp"}
SKIPPED = {"node_modules"}


def files_by_name(root):
    """Each C or C++ file name under ROOT and the paths (relative to ROOT's parent) that have it."""
    found = {}

    def fail(error):
        raise error

    for folder, subfolders, files in os.walk(root, onerror=fail):
        subfolders[:] = sorted(d for d in subfolders if d not in SKIPPED)
        for name in sorted(files):
            if pathlib.Path(name).suffix in SUFFIXES:
                path = pathlib.Path(folder, name).relative_to(root.parent)
                found.setdefault(name, []).append(path)
    return found


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tests", required=True, type=pathlib.Path)
    args = parser.parse_args(argv)
    if not args.tests.is_dir():
        print(f"test_file_names: {args.tests}: no such folder", file=sys.stderr)
        return 2
    try:
        found = files_by_name(args.tests.resolve())
    except OSError as e:
        print(f"test_file_names: {e}", file=sys.stderr)
        return 2
    shared = {name: paths for name, paths in found.items() if len(paths) > 1}
    for name, paths in sorted(shared.items()):
        print(f"test_file_names: {name} is the name of {len(paths)} files: "
              + ", ".join(str(p) for p in paths))
    if shared:
        print("test_file_names: name each file for what it tests (tests/README.md, \"Layout\")")
        return 1
    print(f"test_file_names: {len(found)} C and C++ files in {args.tests}, each name once")
    return 0


if __name__ == "__main__":
    sys.exit(main())
