#!/usr/bin/python3
"""Tests of test_file_names.py on small trees made in a temporary folder."""
import contextlib
import io
import pathlib
import sys
import tempfile
import unittest

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.dont_write_bytecode = True   # no __pycache__ in the source tree
import test_file_names  # noqa: E402


def run(files):
    """test_file_names.py on a tests/ folder holding FILES (paths below it); exit status, output."""
    with tempfile.TemporaryDirectory() as top:
        tests = pathlib.Path(top, "tests")
        tests.mkdir()
        for name in files:
            path = tests / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text("")
        out = io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            status = test_file_names.main(["--tests", str(tests)])
        return status, out.getvalue()


class TestFileNames(unittest.TestCase):
    def test_each_name_once_passes(self):
        status, out = run(["codec/command_packets_test.cpp", "sim/commands_test.cpp",
                           "support/harness.hpp", "CMakeLists.txt", "sim/CMakeLists.txt"])
        self.assertEqual(status, 0, out)
        self.assertIn("3 C and C++ files", out)

    def test_a_name_in_two_folders_fails_naming_both(self):
        status, out = run(["codec/commands_test.cpp", "sim/commands_test.cpp", "sim/power_test.cpp"])
        self.assertEqual(status, 1, out)
        self.assertIn("commands_test.cpp is the name of 2 files: tests/codec/commands_test.cpp, "
                      "tests/sim/commands_test.cpp", out)
        self.assertNotIn("power_test.cpp", out)

    def test_headers_count_too(self):
        status, out = run(["service/harness.hpp", "support/harness.hpp"])
        self.assertEqual(status, 1, out)
        self.assertIn("harness.hpp is the name of 2 files", out)

    def test_npm_packages_are_not_looked_in(self):
        status, out = run(["mcap/node_modules/a/index.h", "browser/node_modules/b/index.h", "mcap/index.h"])
        self.assertEqual(status, 0, out)

    def test_a_missing_folder_is_bad_usage(self):
        out = io.StringIO()
        with contextlib.redirect_stderr(out):
            status = test_file_names.main(["--tests", "/nonexistent/tests"])
        self.assertEqual(status, 2)
        self.assertIn("no such folder", out.getvalue())


if __name__ == "__main__":
    unittest.main()
