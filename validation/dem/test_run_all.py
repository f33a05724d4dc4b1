"""Tests of validation/dem/run_all.py: which scripts it runs, how it stamps a case with
its machine, and the report it writes. Run by ctest (ValidationScripts.DemHelpers) or
by hand: /usr/bin/python3 -m unittest discover -s validation/dem -p 'test_*.py'"""
import ast
import importlib
import inspect
import json
import os
import subprocess
import sys
import tempfile
import time
import unittest
from unittest import mock

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run_all  # noqa: E402


def summary(name, passed, **extra):
    s = {"name": name, "title": f"Case {name}", "thesis": "§2.6", "description": "What it does.",
         "command": f"validation/dem/{name}.py", "date": "2026-12-02 05:00", "run_time_s": 75.0,
         "pass": passed, "figures": [], "notes": ["a note"],
         "checks": [{"quantity": "angle | deg", "measured": 35.123456, "thesis": 36,
                     "tolerance": "±3", "pass": passed},
                    {"quantity": "reported", "measured": 1, "thesis": None, "tolerance": None,
                     "pass": None}]}
    s.update(extra)
    return s


class Scripts(unittest.TestCase):
    def test_runs_the_case_scripts_only(self):
        names = [os.path.basename(p) for p in run_all.scripts()]
        self.assertIn("bouncing_sphere.py", names)
        for name in names:
            self.assertFalse(name.startswith(("_", "test_")), name)
            self.assertNotEqual(name, "run_all.py")

    def test_every_script_takes_the_options_run_all_passes(self):
        # run_all calls each script with --build DIR, and --quick under `run_all --quick`.
        for path in run_all.scripts():
            usage = subprocess.run([sys.executable, path, "--help"], capture_output=True,
                                   text=True, check=True).stdout
            for option in ("--build", "--quick"):
                self.assertIn(option, usage, os.path.basename(path))


class SharedFunctions(unittest.TestCase):
    def test_every_call_to_a_function_of_another_script_fits_its_signature(self):
        # The scripts share functions (`from crosses_tangential_map import classify`); when
        # one gains a required argument, a script still calling it the old way fails only
        # after hours of runs (crosses_gate_effect, 2026-12-06). Each such call is bound
        # to the function's signature here, with placeholders for the arguments.
        checked = 0
        for path in run_all.scripts() + [os.path.join(run_all.HERE, "_outputs.py")]:
            with open(path) as f:
                tree = ast.parse(f.read(), path)
            imported = {}
            for node in ast.walk(tree):
                if (isinstance(node, ast.ImportFrom) and node.module
                        and os.path.exists(os.path.join(run_all.HERE, node.module + ".py"))):
                    module = importlib.import_module(node.module)
                    for alias in node.names:
                        member = getattr(module, alias.name)
                        if inspect.isfunction(member):
                            imported[alias.asname or alias.name] = member
            for node in ast.walk(tree):
                if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                        and node.func.id in imported):
                    continue
                if any(isinstance(a, ast.Starred) for a in node.args) or any(
                        k.arg is None for k in node.keywords):
                    continue  # *args or **kwargs: not bindable from the text
                signature = inspect.signature(imported[node.func.id])
                try:
                    signature.bind(*node.args, **{k.arg: k.value for k in node.keywords})
                except TypeError as e:
                    self.fail(f"{os.path.basename(path)}:{node.lineno}: {node.func.id}: {e}")
                checked += 1
        self.assertGreater(checked, 50)


class Cells(unittest.TestCase):
    def test_formats(self):
        self.assertEqual(run_all.cell(None), "—")
        self.assertEqual(run_all.cell(35.123456), "35.12")
        self.assertEqual(run_all.cell("a | b"), "a \\| b")  # a table cell keeps its bar
        self.assertEqual(run_all.verdict(None), "—")
        self.assertEqual(run_all.verdict(True), "**PASS**")
        self.assertEqual(run_all.verdict(False), "**FAIL**")
        self.assertEqual(run_all.fmt_time(None), "—")
        self.assertEqual(run_all.fmt_time(2.5), "2.50 s")
        self.assertEqual(run_all.fmt_time(75), "75 s")
        self.assertEqual(run_all.fmt_time(1800), "30.0 min")


class Report(unittest.TestCase):
    META = {"date": "2026-12-02 06:00", "cpu": "Test CPU", "nproc": 2, "commit": "abc1234",
            "build": "build", "quick": False}

    def test_lists_each_case_with_its_graded_checks_and_machine(self):
        text = run_all.report([("good", summary("good", True, cpu="Xeon", nproc=2,
                                                commit="f00")),
                               ("bad", summary("bad", False)),
                               ("missing", None)], self.META)
        self.assertIn("Report written 2026-12-02 06:00 on Test CPU (2 cores", text)
        # Ungraded checks (pass None) do not count: 1 of 1 graded.
        self.assertIn("| [Case good](#good) | §2.6 | 1/1 | **PASS** | 75 s |", text)
        self.assertIn("| [Case bad](#bad) | §2.6 | 0/1 | **FAIL** | 75 s |", text)
        self.assertIn("| [missing](#missing) | — | — | **not run** | — |", text)
        self.assertIn("It counts as not passed.", text)
        self.assertIn("on Xeon (2 cores), commit `f00`", text)
        self.assertIn("| angle \\| deg | 35.12 | 36 | ±3 | **PASS** |", text)
        self.assertIn("- a note", text)
        # A case without a machine stamp says nothing about one.
        bad = text[text.index('<a id="bad">'):]
        self.assertIn("Run on 2026-12-02 05:00, run time 75 s. Result: **FAIL**.", bad)

    def test_a_case_without_summary_says_whether_its_runs_were_started(self):
        with tempfile.TemporaryDirectory() as tmp, \
                mock.patch.object(run_all, "RESULTS", tmp):
            os.makedirs(os.path.join(tmp, "runs", "started", "L4cm_1300"))
            os.makedirs(os.path.join(tmp, "runs", "empty"))
            text = run_all.report([("started", None), ("empty", None), ("never", None)],
                                  self.META)
        self.assertIn("| [started](#started) | — | — | **FAIL** (unfinished: no summary) | — |",
                      text)
        self.assertIn("| [empty](#empty) | — | — | **not run** | — |", text)
        # A script that failed in this call without a summary says so, runs or none.
        failed = run_all.report([("never", None)], self.META, failed_now={"never"})
        self.assertIn("| [never](#never) | — | — | **FAIL** (no summary) | — |", failed)
        self.assertIn("its script failed in this run of run_all.py", failed)
        self.assertIn("| [never](#never) | — | — | **not run** | — |", text)
        started = text[text.index('<a id="started">'):text.index('<a id="empty">')]
        self.assertIn("its runs so far are in", started)
        self.assertIn("runs/started", started)

    def test_a_summary_written_from_older_runs_gives_when_they_ran(self):
        later = summary("crosses_later", True, date="2026-12-06 16:47",
                        runs_utc=["2026-11-30 09:11", "2026-12-01 10:41"])
        same_day = summary("same_day", True, runs_utc=["2026-12-02 03:00", "2026-12-02 04:10"])
        text = run_all.report([("crosses_later", later), ("same_day", same_day)], self.META)
        self.assertIn("Runs 2026-11-30 09:11 to 2026-12-01 10:41 UTC, summary written "
                      "2026-12-06 16:47, run time", text)
        self.assertIn("Runs 2026-12-02 03:00 to 04:10 UTC, summary written 2026-12-02 05:00",
                      text)
        # the notes on older models go by the runs: these ran before the contact patches
        self.assertIn("as in thesis §2.3: crosses_later.", text)

    def test_flags_cases_run_before_the_storage_sort(self):
        old = summary("old", True, date="2026-11-20 10:00")
        text = run_all.report([("old", old)], self.META)
        self.assertIn("1 of these 1 cases were run before the particle storage sort "
                      "(2026-11-23 23:30) by earlier builds: old. ", text)

    def test_names_the_cases_of_crosses_run_with_the_corners_torsional_spring(self):
        point = summary("crosses_point", True, date="2026-12-01 10:00")
        corners = summary("crosses_corners", True, date="2026-12-05 19:50")
        spread = summary("crosses_spread", True, date="2026-12-05 22:25")
        later = summary("crosses_later", True, date="2026-12-06 10:00",
                        runs_utc=["2026-12-05 08:00", "2026-12-05 09:00"])
        spheres = summary("spheres", True, date="2026-12-05 19:50")
        cases = [(s["name"], s) for s in (point, corners, spread, later, spheres)]
        flagged = [line for line in run_all.report(cases, self.META).splitlines()
                   if "before their torsional spring was spread" in line]
        self.assertEqual(len(flagged), 1)
        self.assertIn("2 cases of crosses", flagged[0])
        self.assertIn("corners: crosses_corners, crosses_later. ", flagged[0])
        text = run_all.report([("crosses_spread", spread), ("spheres", spheres)], self.META)
        self.assertNotIn("torsional spring", text)

    def test_names_the_cases_of_crosses_run_with_one_contact_point(self):
        old = summary("crosses_old", True, date="2026-11-30 10:00")
        new = summary("crosses_new", True, date="2026-12-02 17:00")
        spheres = summary("spheres_old", True, date="2026-11-30 10:00")
        text = run_all.report([("crosses_old", old), ("crosses_new", new),
                               ("spheres_old", spheres)], self.META)
        flagged = [line for line in text.splitlines() if "ran before the contact patches" in line]
        self.assertEqual(len(flagged), 1)
        self.assertIn("1 cases of crosses", flagged[0])
        self.assertIn("as in thesis §2.3: crosses_old.", flagged[0])
        self.assertNotIn("crosses_new", flagged[0])
        self.assertNotIn("spheres_old", flagged[0])
        text = run_all.report([("crosses_new", new), ("spheres_old", spheres)], self.META)
        self.assertNotIn("ran before the contact patches", text)


class StampHardware(unittest.TestCase):
    def test_stamps_only_a_summary_written_by_this_run(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "case.json")
            with open(path, "w") as f:
                json.dump({"name": "case"}, f)
            written = os.path.getmtime(path)
            run_all.stamp_hardware(path, written + 10, "build")  # written before the run
            with open(path) as f:
                self.assertEqual(json.load(f), {"name": "case"})
            run_all.stamp_hardware(path, written - 10, "build-x")
            with open(path) as f:
                s = json.load(f)
            self.assertEqual(s["name"], "case")
            self.assertEqual(s["build"], "build-x")
            self.assertGreaterEqual(s["nproc"], 1)
            self.assertTrue(s["cpu"] and s["commit"])
            self.assertEqual(os.listdir(tmp), ["case.json"])  # no temporary left

    def test_a_missing_summary_is_left_missing(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "none.json")
            run_all.stamp_hardware(path, time.time() - 10, "build")
            self.assertFalse(os.path.exists(path))


if __name__ == "__main__":
    unittest.main()
