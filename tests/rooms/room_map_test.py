#!/usr/bin/python3
"""Tests of room_map.py: the real docs/design.md and the build's link map ($PMU_LINK_MAP,
which ctest sets) copied, one edit per table row.

Every edit names text that must occur exactly once, so a row breaks loudly when the map it
edits changes instead of passing for the wrong reason.
"""
import contextlib
import io
import os
import pathlib
import sys
import tempfile
import unittest

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.dont_write_bytecode = True   # no __pycache__ in the source tree
import room_map  # noqa: E402

LINK_MAP = pathlib.Path(os.environ.get("PMU_LINK_MAP", ROOT / "build/dev/tests/rooms/link_map.tsv"))
CONFIG_ROW = ("| `pmu::codec`, `pmu::command`, `pmu::security`, `pmu::alarms`, `pmu::baseline`, "
              "`pmu::dds_settings`, `pmu::redundancy` / `pmu::files`, `pmu::version` |")


def edit(name, old, new):
    """Replaces OLD (once) in the copy of file NAME ("map" or "links")."""
    def apply(files):
        f = files[name]
        text = f.read_text()
        assert text.count(old) == 1, f"{name}: {old!r} occurs {text.count(old)} times, not once"
        f.write_text(text.replace(old, new))
    return apply


def append(name, text):
    def apply(files):
        with files[name].open("a") as f:
            f.write(text)
    return apply


# name, edit, exit status, strings the output must contain
CASES = [
    ("the map as it is", None, 0, ["agrees with the build"]),
    ("a private link the map lacks",
     edit("map", CONFIG_ROW, CONFIG_ROW.replace("`pmu::files`, ", "")), 1,
     ["pmu::config: the build links pmu::files PRIVATE, the map does not",
      "pmu::config: write its links cell as `pmu::codec`, `pmu::command`, `pmu::security`, "
      "`pmu::alarms`, `pmu::baseline`, `pmu::dds_settings`, `pmu::redundancy` / `pmu::files`, `pmu::version`"]),
    ("a link the build lacks",
     edit("map", "| `pmu::session`, `pmu::command` |", "| `pmu::session`, `pmu::command`, `pmu::dds` |"), 1,
     ["pmu::dispatch: the map says it links pmu::dds PUBLIC, the build does not"]),
    ("a public link written as private",
     edit("map", "| `pmu::sim`, `pmu::transport` |", "| `pmu::sim` / `pmu::transport` |"), 1,
     ["pmu::sim_runner: the build links pmu::transport PUBLIC, the map does not",
      "pmu::sim_runner: the map says it links pmu::transport PRIVATE, the build does not"]),
    ("a link in the build the map lacks",
     edit("links", "pmu::alarms\tSTATIC_LIBRARY\tservice/alarms/\tpmu::codec\tpmu::warnings",
          "pmu::alarms\tSTATIC_LIBRARY\tservice/alarms/\tpmu::codec\tpmu::files,pmu::warnings"), 1,
     ["pmu::alarms: the build links pmu::files PRIVATE, the map does not",
      "write its links cell as `pmu::codec` / `pmu::files`"]),
    ("a target the map has no row for",
     append("links", "pmu::pmuctl_verbs\tSTATIC_LIBRARY\ttools/pmuctl/verbs/\tpmu::dds\tpmu::warnings\t\n"), 1,
     ["pmu::pmuctl_verbs: the build has this target (tools/pmuctl/verbs/) and the map no row for it; "
      "add one: | `pmu::pmuctl_verbs` | `tools/pmuctl/verbs/` | what it holds | `pmu::dds` |"]),
    ("a row for no target",
     edit("map", "| `pmu::mcap` |", "| `pmu::mcap_reader` |"), 1,
     ["pmu::mcap_reader: the map has a row for it and the build no such target",
      "pmu::mcap: the build has this target"]),
    ("the links of a cell in another order",
     edit("map", "| `pmu::sim`, `pmu::transport` |", "| `pmu::transport`, `pmu::sim` |"), 0,
     ["agrees with the build"]),
    ("pmu::warnings written in a cell",
     edit("map", "| `pmu::sim`, `pmu::transport` |", "| `pmu::sim`, `pmu::transport` / `pmu::warnings` |"), 1,
     ["pmu::sim_runner: the map says it links pmu::warnings PRIVATE, the build does not"]),
    ("a link not in backticks",
     edit("map", "| `pmu::sim`, `pmu::transport` |", "| `pmu::sim`, pmu::transport |"), 2,
     ["design.md:", "'pmu::transport' in the links cell is no `target`"]),
    ("two rows for one target",
     edit("map", "| `pmu::mcap` |", "| `pmu::codec` |"), 2,
     ["pmu::codec has a row already"]),
    ("no links column",
     edit("map", "| target | folder | holds | links |", "| target | folder | holds | uses |"), 2,
     ["no table with a 'links' column under '## Folders'"]),
]


class RoomMap(unittest.TestCase):
    def run_case(self, change):
        with tempfile.TemporaryDirectory() as tmp:
            files = {"map": pathlib.Path(tmp) / "design.md", "links": pathlib.Path(tmp) / "link_map.tsv"}
            files["map"].write_text((ROOT / "docs/design.md").read_text())
            files["links"].write_text(LINK_MAP.read_text())
            if change:
                change(files)
            out, err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                status = room_map.main(["--map", str(files["map"]), "--links", str(files["links"])])
            return status, out.getvalue() + err.getvalue()

    def test_cases(self):
        for name, change, status, expected in CASES:
            with self.subTest(name):
                got, output = self.run_case(change)
                self.assertEqual(got, status, output)
                for text in expected:
                    self.assertIn(text, output)


if __name__ == "__main__":
    unittest.main()
