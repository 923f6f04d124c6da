#!/usr/bin/python3
"""Tests of idl_layout.py: the real idl/ and idl/versions/ copied, one edit per table row.

Every edit names text that must occur exactly once, so a row breaks loudly when the IDL it
edits changes instead of passing for the wrong reason. The contract version is
$PMU_CONTRACT_VERSION (ctest sets it) or that of cmake/install_dirs.cmake.
"""
import contextlib
import io
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.dont_write_bytecode = True   # no __pycache__ in the source tree
import idl_layout  # noqa: E402


def _contract():
    if os.environ.get("PMU_CONTRACT_VERSION"):
        return int(os.environ["PMU_CONTRACT_VERSION"])
    text = (ROOT / "cmake" / "install_dirs.cmake").read_text()
    return int(re.search(r"set\(PMU_CONTRACT_VERSION (\d+)\)", text).group(1))


N = _contract()
OLD, NEW = f"module v{N} {{", f"module v{N + 1} {{"


# Edits: each takes the copy's root and changes it.
def edit(path, old, new):
    def apply(root):
        f = root / path
        text = f.read_text()
        assert text.count(old) == 1, f"{path}: {old!r} occurs {text.count(old)} times, not once"
        f.write_text(text.replace(old, new))
    return apply


def edit_re(path, pattern, new):
    def apply(root):
        f = root / path
        text, count = re.subn(pattern, new, f.read_text(), flags=re.S)
        assert count == 1, f"{path}: /{pattern}/ matches {count} times, not once"
        f.write_text(text)
    return apply


def every_idl(old, new, under="idl"):
    def apply(root):
        for f in sorted((root / under).glob("*.idl")):
            edit(f.relative_to(root), old, new)(root)
    return apply


def keep(version):
    """What a bump does besides the module: idl/*.idl kept as idl/versions/v<version>."""
    def apply(root):
        (root / f"idl/versions/v{version}").mkdir()
        for f in (root / "idl").glob("*.idl"):
            shutil.copy(f, root / f"idl/versions/v{version}" / f.name)
    return apply


BUMP_HINT = "bump the contract's major version"
CONVERTER = "needs a converter"
# The list of the types the service converts from contract N-1, as ctest's guard reads it.
CONVERTED = "dds/include/pmu/dds/previous_contract.hpp"
CONVERTED_NAMES = sorted(idl_layout.converted_types(ROOT / CONVERTED))

# name, edits, status, strings the output must contain, where (file, text: the finding's
# file:line is that of the text's first line), the contract (default N), strings it must not
# contain.
ROWS = [
    # Compatible: exit 0.
    ("comment_changed", [edit("idl/state.idl", "// pmu/health: kept current", "// pmu/health: always current")],
     0, ["idl layout: "]),
    ("struct_added", [edit("idl/state.idl", "  struct Health {",
                           "  struct Restart { @key string<15> vehicle; unsigned long count; };\n  struct Health {")],
     0, [f"idl/versions/v{N}"]),
    ("type_moved_to_another_file", [
        edit_re("idl/command.idl", r"  enum CommandResult \{[^}]*\};\n", ""),
        edit("idl/state.idl", "  enum HealthState",
             "  enum CommandResult { COMPLETED, REJECTED, DENIED, UNSUPPORTED, TIMEOUT, FAILED, IN_PROGRESS };\n"
             "  enum HealthState")],
     0, []),
    ("same_types_spelled_otherwise", [
        edit("idl/state.idl", "@key DeviceKind kind;", f"@key pmu::v{N}::DeviceKind kind;"),
        edit("idl/state.idl", "    HealthState state;", f"    ::pmu::v{N}::HealthState state;"),
        edit("idl/state.idl", "unsigned short serial_number;", "uint16 serial_number;"),
        edit("idl/state.idl", "sequence<string<31>, 16> features;", "sequence<string<0x1F>, 020> features;")],
     0, []),
    ("bound_from_constant_expression", [
        edit("idl/state.idl", "  struct Health {",
             "  const unsigned short NAME_LENGTH = (4 << 2) - 1;\n  struct Health {"),
        edit_re("idl/state.idl", r"(struct Health \{\n    @key )string<15>", r"\1string<NAME_LENGTH>")],
     0, []),
    ("typedef_of_the_same_type", [
        edit("idl/state.idl", "  struct Health {", "  typedef string<15> Name;\n  struct Health {"),
        edit_re("idl/state.idl", r"(struct Health \{\n    @key )string<15>", r"\1Name")],
     0, []),
    ("major_bump_same_layout", [every_idl(OLD, NEW), keep(N + 1)], 0, [f"module v{N + 1}"], None, N + 1),

    # Layout changes of idl/ against idl/versions/vN: exit 1, (b).
    ("member_added", [edit("idl/state.idl", "unsigned long long publish_failures;",
                           "unsigned long long publish_failures;\n    unsigned long long restarts;")],
     1, ["pmu::Health: member restarts added", BUMP_HINT, f"PMU_CONTRACT_VERSION {N + 1}", f"module v{N + 1}",
         f"idl/versions/v{N + 1}", "docs/interface.md section 10"], ("idl/state.idl", "restarts;")),
    ("member_removed", [edit("idl/state.idl", "    unsigned long long rx_dropped;", "    //")],
     1, ["pmu::Health: member rx_dropped removed", f"idl/versions/v{N}/state.idl:", BUMP_HINT],
     ("idl/state.idl", "struct Health {")),
    ("members_swapped", [edit_re("idl/state.idl", r"(unsigned long long frames_received;)[^\n]*\n(\s*)"
                                 r"(unsigned long long frames_sent;)", r"\3\n\2\1")],
     1, ["pmu::Health: members reordered", "frames_received, frames_sent", "frames_sent, frames_received", BUMP_HINT],
     ("idl/state.idl", "frames_sent;")),
    ("string_bound", [edit("idl/command.idl", "string<15> vehicle;            // the vehicle whose service executes",
                           "string<31> vehicle;            // the vehicle whose service executes")],
     1, [f"pmu::Command: member vehicle: string<15> in v{N}, string<31> in idl", BUMP_HINT],
     ("idl/command.idl", "string<31> vehicle;")),
    ("sequence_bound", [edit("idl/state.idl", "sequence<string<31>, 16> features;",
                             "sequence<string<31>, 32> features;")],
     1, ["pmu::DeviceInfo: member features: sequence<string<31>,16>", "sequence<string<31>,32> in idl"],
     ("idl/state.idl", "features;")),
    ("member_type", [edit("idl/telemetry.idl", "float generator_rpm;", "double generator_rpm;")],
     1, ["pmu::Status: member generator_rpm: float", "double in idl"],
     ("idl/telemetry.idl", "generator_rpm;")),
    ("referenced_type", [edit("idl/state.idl", "    BusState bus_state;", "    HealthState bus_state;")],
     1, ["pmu::Health: member bus_state: pmu::BusState", "pmu::HealthState in idl"]),
    ("key_dropped", [edit("idl/state.idl", "@key DeviceKind kind;", "DeviceKind kind;")],
     1, ["pmu::Health: member kind: @key dropped"], ("idl/state.idl", "DeviceKind kind;")),
    ("key_added", [edit("idl/command.idl", "    string<63> request_id;         // chosen",
                        "    @key string<63> request_id;    // chosen")],
     1, ["pmu::Command: member request_id: @key added"]),
    ("enum_literal_added", [edit("idl/state.idl", "enum HealthState { UNKNOWN, ONLINE, STALE, OFFLINE };",
                                 "enum HealthState { UNKNOWN, ONLINE, STALE, OFFLINE, RETIRED };")],
     1, ["pmu::HealthState: literal RETIRED added at position 5", BUMP_HINT], ("idl/state.idl", "RETIRED")),
    ("enum_literals_swapped", [edit("idl/state.idl", "enum BusState { UP, ERROR_WARNING,",
                                    "enum BusState { ERROR_WARNING, UP,")],
     1, ["pmu::BusState: literals reordered"]),
    ("member_renamed", [edit("idl/telemetry.idl", "long battery_a_mah;", "long battery_a_charge;")],
     1, ["pmu::BatteryEnergy: member battery_a_charge added", "member battery_a_mah removed"]),
    ("type_removed", [edit_re("idl/canopen.idl", r"  // pmu/mppt:.*?\n  \};\n", "")],
     1, ["pmu::Mppt: removed", BUMP_HINT], (f"idl/versions/v{N}/canopen.idl", "struct Mppt")),
    ("extensibility_written", [edit("idl/state.idl", "  struct Health {", "  @appendable struct Health {")],
     1, ["pmu::Health: extensibility none written in", "@appendable in idl"]),

    # The version: (a).
    ("module_bumped_contract_not", [every_idl(OLD, NEW)],
     1, [f"module v{N + 1}, but the contract version is {N}", f"module must be v{N}"],
     ("idl/state.idl", f"module v{N + 1}")),
    ("contract_bumped_versions_dir_missing", [every_idl(OLD, NEW)], 1,
     [f"idl/versions/v{N + 1}: missing: it keeps contract {N + 1}'s IDL"], None, N + 1),
    ("contract_bumped_module_not", [keep(N + 1)], 1,
     [f"module v{N}, but the contract version is {N + 1}",
      f"module v{N}, but idl/versions/v{N + 1} keeps contract {N + 1}"],
     ("idl/state.idl", f"module v{N}"), N + 1),
    ("frozen_copy_in_another_module", [every_idl(OLD, NEW, f"idl/versions/v{N}")], 1,
     [f"module v{N + 1}, but idl/versions/v{N} keeps contract {N}"],
     (f"idl/versions/v{N}/state.idl", f"module v{N + 1}")),
    ("types_outside_a_version_module", [every_idl(f"module pmu {{ module v{N} {{", "module pmu { module detail {")],
     1, [f"pmu::detail::Health: outside a version module: the IDL's module must be v{N}",
         "pmu::Health: removed"], ("idl/state.idl", "struct Health {")),

    # Contract N-1 against N: (c).
    ("major_bump_with_layout_change", [
        every_idl(OLD, NEW),
        edit("idl/state.idl", "unsigned long long publish_failures;",
             "unsigned long long publish_failures;\n    unsigned long long restarts;"),
        keep(N + 1)],
     1, [f"pmu::Health: member restarts added at position 16 (not in v{N})",
         f"serving contract {N} as well (v{N + 1}'s types under v{N}'s names) {CONVERTER} for pmu::Health"],
     (f"idl/versions/v{N + 1}/state.idl", "restarts;"), N + 1, [BUMP_HINT]),
]
if N > 1:
    ROWS += [
        ("previous_contract_differs", [edit_re(f"idl/versions/v{N - 1}/command.idl",
                                               r"(struct Command \{.*?)string<15> vehicle;",
                                               r"\1string<31> vehicle;")],
         1, [f"pmu::Command: member vehicle: string<31> in v{N - 1}, string<15> in v{N}", CONVERTER],
         (f"idl/versions/v{N}/command.idl", "string<15> vehicle;"), N, [BUMP_HINT]),
        ("frozen_copy_edited", [edit(f"idl/versions/v{N}/state.idl", "sequence<string<31>, 16> features;",
                                     "sequence<string<31>, 16> features;\n    unsigned long restarts;")],
         1, [f"pmu::DeviceInfo: member restarts removed (in v{N} at idl/versions/v{N}/state.idl:", BUMP_HINT,
             f"pmu::DeviceInfo: member restarts added at position 11 (not in v{N - 1})", CONVERTER]),
        # The converted types: a layout change from N-1 is allowed for the types the list names
        # only, and the list names types of N-1 only.
        ("converted_type_not_listed", [edit_re(CONVERTED, r'(kConvertedTypes\[\] = \{[^}]*)"Status",? ?', r"\1")],
         1, [f"pmu::Status: member generator_rpm: unsigned short in v{N - 1}, float in v{N}",
             f"{CONVERTER} for pmu::Status (dds/src/previous_contract.cpp), named in kConvertedTypes of {CONVERTED}"],
         (f"idl/versions/v{N}/telemetry.idl", "float generator_rpm;")),
        ("converted_type_unknown", [edit_re(CONVERTED, r"(kConvertedTypes\[\] = \{)", r'\1"Gone", ')],
         1, [f"{CONVERTED}: pmu::Gone: named in kConvertedTypes, but contract {N - 1} has no such type"]),
        ("converted_list_missing", [edit_re(CONVERTED, r"kConvertedTypes\[\]", "kTypes[]")],
         2, [f"{CONVERTED}: no list kConvertedTypes[] = {{...}} of the types the service converts"]),
        ("converted_list_bad_name", [edit_re(CONVERTED, r"(kConvertedTypes\[\] = \{)", r'\1"pmu::X", ')],
         2, ["kConvertedTypes: 'pmu::X' is not a type name"]),
    ]
ROWS += [
    # IDL the checker does not understand: exit 2, naming the file and line.
    ("union", [edit("idl/state.idl", "  struct Health {",
                    "  union Choice switch (long) { case 1: long a; };\n  struct Health {")],
     2, ["not IDL this checker parses"], ("idl/state.idl", "union Choice")),
    ("unknown_member_annotation", [edit("idl/state.idl", "    float last_frame_age;",
                                        "    @optional float last_frame_age;")],
     2, ["annotation @optional on a member: not understood"], ("idl/state.idl", "@optional")),
    ("unknown_struct_annotation", [edit("idl/state.idl", "  struct Health {", "  @nested struct Health {")],
     2, ["annotation @nested on a struct: not understood"], ("idl/state.idl", "@nested")),
    ("undeclared_type", [edit("idl/state.idl", "    HealthState state;", "    HealthStatus state;")],
     2, ["HealthStatus: not declared in these files"], ("idl/state.idl", "HealthStatus")),
    ("non_integer_bound", [edit("idl/state.idl", "sequence<string<31>, 16> features;",
                                "sequence<string<31>, 16.5> features;")],
     2, ["floating_pt_literal in a constant expression: only integers are understood"], ("idl/state.idl", "16.5")),
    ("syntax_error", [edit("idl/state.idl", "    float last_frame_age;", "    float last_frame_age")],
     2, ["not IDL this checker parses"], ("idl/state.idl", "unsigned long long frames_received;")),
]


def _run(*argv):
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        try:
            status = idl_layout.main(list(argv))
        except SystemExit as e:   # argparse's usage errors
            status = e.code
    return status, out.getvalue()


class Table(unittest.TestCase):
    def setUp(self):
        self.cwd = os.getcwd()
        self.root = pathlib.Path(tempfile.mkdtemp(prefix="idl_layout_"))
        (self.root / "idl").mkdir()
        for f in (ROOT / "idl").glob("*.idl"):
            shutil.copy(f, self.root / "idl")
        shutil.copytree(ROOT / "idl" / "versions", self.root / "idl" / "versions")
        (self.root / CONVERTED).parent.mkdir(parents=True)
        shutil.copy(ROOT / CONVERTED, self.root / CONVERTED)
        os.chdir(self.root)   # the findings then name idl/... as in the source tree

    def tearDown(self):
        os.chdir(self.cwd)
        shutil.rmtree(self.root)

    def check(self, contract=N):
        # The list names the types converted from contract N-1 to N: for another contract it
        # would name the wrong ones.
        converted = ["--converted", CONVERTED] if contract == N else []
        return _run("check", "--idl-dir", "idl", "--versions-dir", "idl/versions", "--contract", str(contract),
                    *converted)

    def row(self, edits, status, expected, where=None, contract=N, absent=()):
        for apply in edits:
            apply(self.root)
        got, out = self.check(contract)
        self.assertEqual(got, status, out)
        for text in expected:
            self.assertIn(text, out)
        for text in absent:
            self.assertNotIn(text, out)
        if where:
            path, text = where
            content = (self.root / path).read_text()
            self.assertIn(text, content)
            line = content[:content.index(text)].count("\n") + 1
            self.assertIn(f"{path}:{line}:", out)

    def test_copy_passes(self):
        status, out = self.check()
        self.assertEqual(status, 0, out)
        if N > 1:
            self.assertIn(f"but the converted {', '.join(CONVERTED_NAMES)}", out)

    def test_converted_types_are_the_only_previous_layout_changes(self):
        # Without the list, every converted type whose layout changed is a finding; no other is.
        if N < 2:
            self.skipTest("no previous contract")
        status, out = _run("check", "--idl-dir", "idl", "--versions-dir", "idl/versions", "--contract", str(N))
        self.assertEqual(status, 1, out)
        named = set(re.findall(r"^idl/versions/v%d/\S+ (pmu::\w+):" % N, out, flags=re.M))
        self.assertTrue(named, out)
        self.assertLessEqual(named, set(CONVERTED_NAMES), out)

    def test_usage_errors(self):
        for argv in ([], ["bogus"], ["check", "--idl-dir", "idl"], ["dump"],
                     ["check", "--idl-dir", "idl", "--versions-dir", "idl/versions", "--contract", "four"],
                     ["check", "--idl-dir", "idl", "--versions-dir", "idl/versions", "--contract", "0"]):
            with self.subTest(argv=argv):
                self.assertEqual(_run(*argv)[0], 2)

    def test_missing_idl_dir(self):
        status, out = _run("check", "--idl-dir", "nowhere", "--versions-dir", "idl/versions", "--contract", str(N))
        self.assertEqual(status, 2, out)
        self.assertIn("nowhere: no .idl files", out)


for name, edits, status, expected, *rest in ROWS:
    setattr(Table, f"test_{name}", lambda self, a=(edits, status, expected, *rest): self.row(*a))


class Layout(unittest.TestCase):
    def test_real_tree_passes(self):
        # As ctest's idl_layout_guard runs it, in a process of its own.
        run = subprocess.run([sys.executable, str(HERE / "idl_layout.py"), "check", "--idl-dir", "idl",
                              "--versions-dir", "idl/versions", "--contract", str(N), "--converted", CONVERTED],
                             cwd=ROOT, capture_output=True, text=True)
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
        self.assertRegex(run.stdout, r"^idl layout: idl \(module v%d, \d+ types\)" % N)

    def test_dump_normalises(self):
        status, out = _run("dump", *sorted(str(f) for f in (ROOT / "idl").glob("*.idl")))
        self.assertEqual(status, 0, out)
        for line in ("struct pmu::Health\n  @key string<15> vehicle\n", "  sequence<string<31>,16> features\n",
                     "  unsigned long long frames_received\n", "  @key pmu::DeviceKind kind\n",
                     "enum pmu::HealthState\n  UNKNOWN\n  ONLINE\n"):
            self.assertIn(line, out)
        self.assertNotIn(f"v{N}", out)

    def test_constant_expressions_and_typedefs(self):
        with tempfile.TemporaryDirectory() as d:
            f = pathlib.Path(d) / "x.idl"
            f.write_text("module m { module v7 {\n"
                         "  const unsigned short HALF = 8;\n"
                         "  const long LEN = (HALF * 2 - 1) << 0x1 /* not - */ >> 1;\n"
                         "  const long ODD = -(017 % 5) + ~0 + 7 / -2 + 100;\n"
                         "  typedef string<LEN> Name;\n"
                         "  typedef long Triple[3];\n"
                         "  @final struct S {\n"
                         "    @key(TRUE) Name a; @key(FALSE) int16 b;\n"
                         "    Triple t[2]; long u[2][3];\n"
                         "    sequence<::m::v7::E> es; string<ODD> c, d;\n"
                         "  };\n"
                         "  enum E { X, Y };\n"
                         "}; };\n")
            status, out = _run("dump", str(f))
        self.assertEqual(status, 0, out)
        self.assertEqual(out, "enum m::E\n  X\n  Y\n@final struct m::S\n  @key string<15> a\n  short b\n"
                              "  long[2][3] t\n  long[2][3] u\n  sequence<m::E> es\n  string<96> c\n  string<96> d\n")


if __name__ == "__main__":
    unittest.main(verbosity=2)
