#!/usr/bin/python3
"""The map of the rooms (docs/design.md, "Folders") against the links the build holds.

  room_map.py --map docs/design.md --links build/dev/tests/rooms/link_map.tsv

The map is the table under "## Folders" whose header has a column "links": one row per
first-party library and program outside tests/ and bench/, its first cell the target
(`pmu::codec`, `pmuctl`), its links cell the first-party targets it links, PUBLIC before a
slash and PRIVATE after it (`pmu::codec`, `pmu::command` / `pmu::files`; — for none).
pmu::warnings, which every target links, and third-party links are not written there.

The link map is what CMake writes at configure time (tests/rooms/CMakeLists.txt): one line a
target, tab-separated: name, type, folder, public links, private links, third-party links.

Exit status: 0 they agree (one summary line), 1 findings (one a line, each naming the row
and the link, and the cell the row should have), 2 bad usage or a map this checker cannot
read (file:line).
"""
import argparse
import pathlib
import re
import sys

IGNORED = {"pmu::warnings"}
NONE = "—"
TARGET_CELL = re.compile(r"^`([A-Za-z0-9_:.\-]+)`$")


class MapError(Exception):
    """A map or link map this checker cannot read: exit 2."""


def cell_text(public, private):
    """The links cell the build's links give, as the map writes it."""
    def names(links):
        return ", ".join(f"`{link}`" for link in links) if links else NONE
    if not private:
        return names(public)
    return f"{names(public)} / {names(private)}"


def parse_links_cell(text, where):
    parts = [p.strip() for p in text.split("/")]
    if len(parts) > 2:
        raise MapError(f"{where}: links cell {text!r} has more than one '/' (PUBLIC / PRIVATE)")
    sets = []
    for part in parts:
        if part in (NONE, ""):
            sets.append([])
            continue
        links = []
        for item in part.split(","):
            m = TARGET_CELL.match(item.strip())
            if not m:
                raise MapError(f"{where}: {item.strip()!r} in the links cell is no `target`")
            links.append(m.group(1))
        sets.append(links)
    if len(sets) == 1:
        sets.append([])
    return sets


def split_row(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def read_map(path):
    """{target: (public, private, line)} from the table under "## Folders" with a links column."""
    lines = path.read_text().splitlines()
    in_folders = False
    header = None
    rows = {}
    for number, line in enumerate(lines, 1):
        if line.startswith("## "):
            if in_folders and header is not None:
                break
            in_folders = line.strip() == "## Folders"
            continue
        if not in_folders:
            continue
        if header is None:
            if line.startswith("|") and "links" in split_row(line):
                header = split_row(line)
                links_column = header.index("links")
            continue
        if not line.startswith("|"):
            break
        cells = split_row(line)
        if set("".join(cells)) <= set("-: "):
            continue  # the separator row
        where = f"{path}:{number}"
        if len(cells) != len(header):
            raise MapError(f"{where}: {len(cells)} cells, the header has {len(header)}")
        m = TARGET_CELL.match(cells[0])
        if not m:
            raise MapError(f"{where}: first cell {cells[0]!r} is no `target`")
        target = m.group(1)
        if target in rows:
            raise MapError(f"{where}: {target} has a row already (line {rows[target][2]})")
        public, private = parse_links_cell(cells[links_column], where)
        rows[target] = (public, private, number)
    if header is None:
        raise MapError(f"{path}: no table with a 'links' column under '## Folders'")
    return rows


def read_link_map(path):
    """{target: (public, private, folder)} as CMake wrote them, pmu::warnings left out."""
    targets = {}
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if not line or line.startswith("#"):
            continue
        fields = line.split("\t")
        if len(fields) != 6:
            raise MapError(f"{path}:{number}: {len(fields)} fields, not 6")
        name, _type, folder, public, private, _third = fields
        targets[name] = tuple([link for link in cell.split(",") if link and link not in IGNORED]
                              for cell in (public, private)) + (folder,)
    return targets


def compare(rows, targets, map_path):
    findings = []
    for target, (public, private, folder) in targets.items():
        if target not in rows:
            findings.append(f"{map_path}: {target}: the build has this target ({folder}) and the "
                            f"map no row for it; add one: | `{target}` | `{folder}` | what it "
                            f"holds | {cell_text(public, private)} |")
            continue
        map_public, map_private, number = rows[target]
        where = f"{map_path}:{number}: {target}"
        for kind, built, written in (("PUBLIC", public, map_public),
                                     ("PRIVATE", private, map_private)):
            for link in built:
                if link not in written:
                    findings.append(f"{where}: the build links {link} {kind}, the map does not")
            for link in written:
                if link not in built:
                    findings.append(f"{where}: the map says it links {link} {kind}, the build does not")
        if (set(public), set(private)) != (set(map_public), set(map_private)):
            findings.append(f"{where}: write its links cell as {cell_text(public, private)}")
    for target, (_public, _private, number) in rows.items():
        if target not in targets:
            findings.append(f"{map_path}:{number}: {target}: the map has a row for it and the "
                            f"build no such target (outside tests/ and bench/); remove the row")
    return findings


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", required=True, type=pathlib.Path)
    parser.add_argument("--links", required=True, type=pathlib.Path)
    args = parser.parse_args(argv)
    try:
        rows = read_map(args.map)
        targets = read_link_map(args.links)
    except (MapError, OSError) as e:
        print(f"room_map: {e}", file=sys.stderr)
        return 2
    findings = compare(rows, targets, args.map)
    for finding in findings:
        print(f"room_map: {finding}")
    if findings:
        print(f"room_map: {args.map} differs from the build's links ({args.links}); the map "
              "describes the build as it is: change the row, or the CMakeLists.txt")
        return 1
    print(f"room_map: {len(rows)} targets, {sum(len(p) + len(q) for p, q, _ in rows.values())} "
          f"first-party links: {args.map} agrees with the build")
    return 0


if __name__ == "__main__":
    sys.exit(main())
