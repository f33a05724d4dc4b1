"""Unit tests of crosses_flow_map's columns and outcomes (run by ctest
ValidationScripts.DemHelpers)."""
import contextlib
import io
import json
import os
import runpy
import sys
import tempfile
import tomllib
import unittest
from unittest import mock

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_dam_break as db  # noqa: E402
import crosses_flow_map as fm  # noqa: E402


class Columns(unittest.TestCase):
    def test_the_memory_cases_column_sets_the_height_per_cross(self):
        # 300 crosses behind a 4 cm gate in a 6 cm deep box stand 17.4-18.3 cm tall
        self.assertAlmostEqual(fm.expected_height(4, 300), 0.175, places=6)
        self.assertAlmostEqual(fm.expected_height(8, 600), 0.175, places=6)
        self.assertAlmostEqual(fm.expected_height(4, 450), 1.5 * 0.175, places=6)

    def test_one_column_of_the_default_map_is_taller_than_20_cm_and_the_others_lower(self):
        tall = [c for c in fm.COLUMNS if fm.expected_height(*c) > fm.TALL_M + 0.03]
        low = [c for c in fm.COLUMNS if fm.expected_height(*c) < fm.TALL_M - 0.02]
        self.assertEqual(tall, [(4, 450)])
        self.assertEqual(len(low), len(fm.COLUMNS) - 1)

    def test_the_pour_starts_above_the_columns_top_and_the_box_is_6_cm_deep(self):
        with open(db.CASE, "rb") as f:
            case = tomllib.load(f)
        top = case["particles"][0]["region_max_m"][2]
        for gate_cm, count in fm.COLUMNS:
            col = fm.column_of(gate_cm, count)
            self.assertGreaterEqual(col.pour_bottom_m, fm.expected_height(gate_cm, count) + 0.05)
            self.assertGreaterEqual(col.pour_bottom_m, 0.28)
            self.assertLess(col.pour_bottom_m + 0.3, top)  # room left to pour
            settings = db.overrides(col)
            self.assertIn(f"obstacle[{db.SIDE_WALL_INDEX}].point_m=[0.0, 0.06, 0.0]", settings)
            self.assertIn(f"particles[0].count={count}", settings)
        self.assertEqual(case["obstacle"][db.SIDE_WALL_INDEX]["name"], "side wall, back")

    def test_seeds_and_folders(self):
        self.assertEqual(fm.seed_settings(db.SEED), [])
        self.assertEqual(fm.seed_settings(1), ["--set", "simulation.seed=1"])
        self.assertNotEqual(fm.folder(4, 300, 1), fm.folder(4, 300, 2))
        self.assertNotEqual(fm.folder(4, 300, 1), fm.folder(8, 300, 1))


def fake_run(folder, gate_removed_at, last_time, settled):
    """A run folder as run_column leaves it, as far as `unfinished` reads it."""
    os.makedirs(folder)
    with open(os.path.join(folder, "obstacles.csv"), "w") as f:
        f.write(f"index,type,remove_at_s,name\n0,plane,inf,floor\n5,box,{gate_removed_at},gate\n")
    with open(os.path.join(folder, "diagnostics.csv"), "w") as f:
        f.write(f"time_s,mean_velocity_m_s\n0,0\n{last_time},1e-4\n")
    with open(os.path.join(folder, "run.log"), "w") as f:
        f.write(f"done: t = {last_time} s, 20000 steps in 1m13s, ended 2026-12-06 17:51:34 UTC"
                + (", settled" if settled else "") + "\n")


class Models(unittest.TestCase):
    def tearDown(self):
        fm.model = fm.SUM
        fm.depth_m = fm.DEPTH_M

    def test_each_model_runs_in_its_own_folders_with_its_overrides(self):
        folders = set()
        for m in (fm.SUM, fm.MEAN, fm.MEAN_POINT):
            fm.model = m
            folders.add(fm.folder(4, 300, 1))
            self.assertTrue(fm.folder(4, 300, 1).startswith(m.runs() + os.sep))
            self.assertTrue(fm.point_folder(4, 300).startswith(m.runs() + os.sep))
            self.assertTrue(m.figure().endswith(os.path.join("figures", m.name + ".png")))
        self.assertEqual(len(folders), 3)
        self.assertEqual(fm.SUM.settings, [])
        self.assertEqual(fm.MEAN.settings, ["--set", 'simulation.element_contacts="mean"'])
        self.assertEqual(fm.MEAN_POINT.settings, ["--set", 'simulation.element_contacts="mean"',
                                                  "--set", 'simulation.flat_contacts="point"'])

    def test_each_narrow_model_has_a_wrapper_of_its_name_that_chooses_it(self):
        # The mean with the patches is mapped in the deep box only (its wrapper:
        # test_the_wrappers_map_their_model_in_the_deep_box).
        here = os.path.dirname(os.path.abspath(__file__))
        flags = [(fm.SUM, None),
                 (fm.MEAN_POINT, '["--element-contacts", "mean", "--flat-contacts", "point"]')]
        for m, chosen_by in flags:
            path = os.path.join(here, m.name + ".py")
            self.assertTrue(os.path.exists(path), m.name)
            if chosen_by:
                with open(path) as f:
                    self.assertIn(f"crosses_flow_map.main({chosen_by}", f.read())

    def test_a_run_takes_the_models_overrides(self):
        calls = []
        with mock.patch.object(fm, "run_column",
                               lambda exe, col, out, threads, extra: calls.append(extra)):
            for m in (fm.SUM, fm.MEAN_POINT):
                fm.model = m
                fm.run_one("sanguis", 4, 150, 1)
        self.assertEqual(calls, [["--set", "simulation.seed=1"],
                                 fm.MEAN_POINT.settings + ["--set", "simulation.seed=1"]])

    def test_the_options_choose_the_model_and_one_point_needs_the_mean(self):
        # Results go to a scratch folder and one seed ends every call before any run or
        # mapping: a lost check cannot touch the maps on disk.
        with tempfile.TemporaryDirectory() as tmp, mock.patch.object(fm, "RESULTS", tmp):
            for argv, chosen in ((["--element-contacts", "mean"], fm.MEAN),
                                 (["--element-contacts", "mean", "--flat-contacts", "point"],
                                  fm.MEAN_POINT),
                                 ([], fm.SUM)):
                err = io.StringIO()
                with contextlib.redirect_stderr(err), self.assertRaises(SystemExit):
                    fm.main(argv + ["--seeds", "1", "--reuse"])
                self.assertIn("at least two packings", err.getvalue())
                self.assertIs(fm.model, chosen)
            err = io.StringIO()
            with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as raised:
                fm.main(["--flat-contacts", "point", "--seeds", "1", "--reuse"])
            self.assertEqual(raised.exception.code, 2)
            self.assertIn("--flat-contacts point runs with", err.getvalue())


class ExperimentsBox(unittest.TestCase):
    """--depth-cm 20: the map in crosses_dam_break's own 20 cm deep box."""

    def setUp(self):
        fm.depth_m = fm.DEEP_M
        fm.model = fm.MEAN_POINT.in_experiments_box()

    def tearDown(self):
        fm.depth_m = fm.DEPTH_M
        fm.model = fm.SUM

    def test_the_deep_columns_have_the_narrow_maps_heights(self):
        deep = [fm.expected_height(*c) for c in fm.DEEP_COLUMNS]
        fm.depth_m = fm.DEPTH_M
        narrow = [fm.expected_height(*c) for c in fm.COLUMNS]
        for d, n in zip(deep[:2] + deep[3:], narrow[:2] + narrow[3:]):
            self.assertAlmostEqual(d, n, places=9)
        # the tall one is the dam break's 1300 crosses, lower than 1500 would stand
        self.assertGreater(deep[2], fm.TALL_M + 0.02)

    def test_the_dam_breaks_columns_are_its_own_and_the_others_are_poured_above_their_top(self):
        self.assertEqual(fm.column_of(4, 1300), db.column(4))
        self.assertEqual(fm.column_of(8, 2000), db.column(8))
        for gate_cm, count in fm.DEEP_COLUMNS:
            col = fm.column_of(gate_cm, count)
            self.assertEqual(col.depth_m, 0.20)
            self.assertNotIn(f"obstacle[{db.SIDE_WALL_INDEX}].point_m", " ".join(db.overrides(col)))
            if (gate_cm, count) not in ((4, 1300), (8, 2000)):
                self.assertGreaterEqual(col.pour_bottom_m,
                                        fm.expected_height(gate_cm, count) + 0.05)

    def test_only_the_dam_breaks_column_and_seed_with_the_same_model_is_its_run(self):
        runs = os.path.join(fm.RESULTS, "runs")
        self.assertEqual(fm.experiments_run(4, 1300, db.SEED),
                         os.path.join(runs, "crosses_dam_break_mean_point", "L4cm_seed3"))
        self.assertIsNone(fm.experiments_run(4, 1300, 1))
        self.assertIsNone(fm.experiments_run(4, 1000, db.SEED))
        self.assertIsNone(fm.experiments_run(4, 1200, db.SEED))
        # the 12 cm gate's 3000 crosses would be poured as the dam break pours them
        self.assertEqual(fm.column_of(12, 3000), db.column(12))
        self.assertIsNotNone(fm.experiments_run(12, 3000, db.SEED))
        fm.model = fm.SUM.in_experiments_box()
        self.assertEqual(fm.experiments_run(8, 2000, db.SEED),
                         os.path.join(runs, "crosses_dam_break", "L8cm_seed3"))
        fm.model = fm.MEAN.in_experiments_box()
        self.assertEqual(fm.experiments_run(4, 1300, db.SEED),
                         os.path.join(runs, "crosses_dam_break_mean", "L4cm_seed3"))
        fm.depth_m = fm.DEPTH_M
        fm.model = fm.SUM
        self.assertIsNone(fm.experiments_run(4, 1300, db.SEED))  # another box

    def test_a_map_without_the_cases_seed_names_the_dam_breaks_pour_of_its_columns(self):
        fm.model = fm.MEAN.in_experiments_box()
        notes = fm.dam_break_pour_notes([(4, 1300), (4, 1000)], [1, 2])
        self.assertEqual(len(notes), 1)
        self.assertIn("Gate 4 cm, 1300 crosses: the case's seed (3) is crosses_dam_break_mean's",
                      notes[0])
        self.assertIn("(--seeds 1 2)", notes[0])
        self.assertIn("crosses_runout", notes[0])
        self.assertEqual(fm.dam_break_pour_notes([(4, 1300)], [1, 2, 3]), [])
        fm.depth_m = fm.DEPTH_M  # the narrow box holds none of the dam break's columns
        self.assertEqual(fm.dam_break_pour_notes([(4, 1300), (4, 450)], [1, 2]), [])

    def test_a_finished_dam_break_run_is_copied_whole_and_an_unfinished_one_is_not(self):
        calls = []
        with tempfile.TemporaryDirectory() as tmp, mock.patch.object(fm, "RESULTS", tmp), \
                mock.patch.object(fm, "run_column",
                                  lambda exe, col, out, threads, extra: calls.append(out)):
            source = fm.experiments_run(4, 1300, db.SEED)
            fake_run(source, 2.6, 4.1, True)
            fm.run_one("sanguis", 4, 1300, db.SEED)
            out = fm.folder(4, 1300, db.SEED)
            self.assertEqual(calls, [])
            self.assertEqual(sorted(os.listdir(out)), sorted(os.listdir(source) + [fm.COPIED_FROM]))
            self.assertFalse(os.path.exists(out + ".partial"))
            copied, date, segment = fm.copied_source(out)
            self.assertEqual(os.path.realpath(copied), os.path.realpath(source))
            self.assertTrue(segment.startswith("done: t = 4.1 s"))
            self.assertIsNone(fm.copied_source(source))
            fm.run_one("sanguis", 4, 1300, db.SEED)  # copied already: neither run nor copied
            self.assertEqual(calls, [])
            fm.run_one("sanguis", 4, 1300, 1)  # another seed: run
            self.assertEqual(calls, [fm.folder(4, 1300, 1)])
            fm.model = fm.MEAN.in_experiments_box()
            fake_run(fm.experiments_run(4, 1300, db.SEED), 2.6, 3.5, False)  # in its collapse
            fm.run_one("sanguis", 4, 1300, db.SEED)
            self.assertEqual(calls[-1], fm.folder(4, 1300, db.SEED))
            self.assertFalse(os.path.exists(calls[-1]))  # run_column, mocked, made nothing

    def test_a_copied_run_is_noted_with_its_own_time_threads_and_stops(self):
        with tempfile.TemporaryDirectory() as tmp, mock.patch.object(fm, "RESULTS", tmp):
            source = fm.experiments_run(4, 1300, db.SEED)
            fake_run(source, 2.6, 4.1, True)  # one segment, 17:50:21-17:51:34 UTC, 73 s
            with open(os.path.join(source, "run.log"), "a") as f:
                f.write("threads         2 requested (small systems use fewer)\n")
            with open(os.path.join(os.path.dirname(source), "PAUSES.txt"), "w") as f:
                f.write("2026-12-06T17:51 stopped for the CI (0.5 min)\n")
            fm.copy_experiments_run(source, fm.folder(4, 1300, db.SEED))
            note = fm.copy_note(4, 1300, db.SEED, fm.folder(4, 1300, db.SEED))
            self.assertIn("crosses_dam_break_mean_point/L4cm_seed3 is copied", note)
            self.assertIn(f"{(73 - 30) / 3600:.2f} h on 2 thread(s), not in this map's run time",
                          note)
            self.assertIn("0.5 min of stops left out", note)
            self.assertNotIn("changed", note)
            with open(os.path.join(source, "run.log"), "a") as f:  # the source ran on
                f.write("done: t = 4.6 s, 20000 steps in 10s, ended 2026-12-07 01:00:00 UTC\n")
            self.assertIn("has changed (or gone) since",
                          fm.copy_note(4, 1300, db.SEED, fm.folder(4, 1300, db.SEED)))

    def test_the_run_time_counts_the_maps_own_runs_less_their_stops_and_no_copy(self):
        with tempfile.TemporaryDirectory() as tmp, mock.patch.object(fm, "RESULTS", tmp):
            with open(os.path.join(tmp, "PAUSES.txt"), "w") as f:
                f.write("2026-12-06T17:51 stopped for the CI (0.5 min)\n")
            stop_list = fm.stops(tmp)
            own = fm.folder(4, 1300, 1)
            fake_run(own, 2.6, 4.1, True)  # 17:50:21-17:51:34 UTC
            duration, stopped_s, intervals, note = fm.accounted(4, 1300, 1, own, stop_list)
            self.assertEqual((duration, stopped_s, len(intervals), note), (43.0, 30.0, 1, None))
            source = fm.experiments_run(4, 1300, db.SEED)
            fake_run(source, 2.6, 4.1, True)
            fm.copy_experiments_run(source, fm.folder(4, 1300, db.SEED))
            duration, stopped_s, intervals, note = fm.accounted(
                4, 1300, db.SEED, fm.folder(4, 1300, db.SEED), stop_list)
            self.assertEqual((duration, stopped_s, intervals), (0.0, 0.0, []))
            self.assertIn("is copied", note)

    def test_the_option_chooses_the_box_and_names_the_map_after_it(self):
        with tempfile.TemporaryDirectory() as tmp, mock.patch.object(fm, "RESULTS", tmp):
            err = io.StringIO()
            with contextlib.redirect_stderr(err), self.assertRaises(SystemExit):
                fm.main(["--element-contacts", "mean", "--flat-contacts", "point",
                         "--depth-cm", "20", "--seeds", "1", "--reuse"])
            self.assertEqual(fm.model.name, "crosses_flow_map_mean_point_deep")
            self.assertEqual(fm.depth_m, 0.20)
            self.assertEqual(fm.command_script(True, True, True),
                             "validation/dem/crosses_flow_map_mean_point_deep.py")
            with contextlib.redirect_stderr(io.StringIO()), self.assertRaises(SystemExit):
                fm.main(["--depth-cm", "20", "--seeds", "1", "--reuse"])
            self.assertEqual(fm.model.name, "crosses_flow_map_deep")
            self.assertEqual(fm.command_script(False, False, True),
                             "validation/dem/crosses_flow_map_deep.py")
            fm.model = fm.MEAN  # the narrow box's mean has no wrapper: the options
            self.assertEqual(fm.command_script(True, False, False), "validation/dem/"
                             "crosses_flow_map.py --element-contacts mean")
            fm.model = fm.MEAN_POINT.in_experiments_box()._replace(name="crosses_flow_map_x")
            self.assertEqual(fm.command_script(True, True, True), "validation/dem/"
                             "crosses_flow_map.py --element-contacts mean --flat-contacts "
                             "point --depth-cm 20")
            err = io.StringIO()
            with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as raised:
                fm.main(["--depth-cm", "12", "--seeds", "1", "2", "--reuse"])
            self.assertEqual(raised.exception.code, 2)
            self.assertIn("--depth-cm", err.getvalue())

    def test_the_default_columns_follow_the_box(self):
        self.assertEqual(fm.default_columns(False, False), fm.COLUMNS)
        self.assertEqual(fm.default_columns(False, True), fm.QUICK_COLUMNS)
        self.assertEqual(fm.default_columns(True, False), fm.DEEP_COLUMNS)
        self.assertEqual(fm.default_columns(True, True), fm.DEEP_QUICK_COLUMNS)

    def test_the_wrappers_map_their_model_in_the_deep_box(self):
        here = os.path.dirname(os.path.abspath(__file__))
        for m, flags in ((fm.MEAN_POINT, ["--element-contacts", "mean", "--flat-contacts",
                                          "point"]), (fm.MEAN, ["--element-contacts", "mean"]),
                         (fm.SUM, [])):
            given = []
            with mock.patch.object(fm, "main", lambda argv: given.append(argv) or 0), \
                    mock.patch.object(sys, "argv", ["wrapper", "--columns", "4:1300"]), \
                    self.assertRaises(SystemExit) as raised:
                runpy.run_path(os.path.join(here, m.in_experiments_box().name + ".py"),
                               run_name="__main__")
            self.assertEqual(raised.exception.code, 0)
            self.assertEqual(given, [flags + ["--depth-cm", "20", "--columns", "4:1300"]])


class Runs(unittest.TestCase):
    def test_a_call_for_one_column_maps_every_finished_one(self):
        summary = {"H0_m": 0.21, "aspect_ratio_H0_over_L0": 5.4, "runout_ratio": 6.0,
                   "height_ratio_H0_over_Hinf": 3.0, "peak_mean_speed_over_sqrt_gH0": 0.2,
                   "regime": 2}
        mapped, written = [], []
        row = {"H0_m": "0.2", "aspect_ratio_H0_over_L0": "5", "outcome": "collapsed"}
        with mock.patch.multiple(
                fm, unfinished=lambda run: None, stops=lambda runs: [],
                finished_columns=lambda seeds: [(4, 500), (4, 1300)],
                map_columns=lambda exe, cols, seeds: mapped.append(cols) or
                {c: row for c in cols},
                read_summary=lambda run: summary, opening_time=lambda run: 2.6,
                stopped=lambda run, t: "at rest", wall_time=lambda run: 60.0,
                accounted=lambda g, n, s, run, st: (60.0, 0.0, [], None),
                at_rest_at_opening=lambda run, t: 1e-4, dropped_columns=lambda cols: [],
                write_summary=lambda s, *rest: written.append(s)), \
                contextlib.redirect_stdout(io.StringIO()):
            fm.main(["--depth-cm", "20", "--columns", "4:1000", "--reuse"])
            # Without --columns: the defaults, and a finished column beyond them.
            fm.finished_columns = lambda seeds: [(2.5, 100)]
            fm.main(["--depth-cm", "20", "--reuse"])
        self.assertEqual(mapped, [[(4, 500), (4, 1000), (4, 1300)],
                                  [(2.5, 100)] + fm.DEEP_COLUMNS])
        self.assertIn("--columns 4:500 4:1000 4:1300", written[0]["command"])
        self.assertIn("--columns 2.5:100 4:500 4:1000 4:1300 8:1000 8:2000",
                      written[1]["command"])
        fm.model = fm.SUM

    def test_a_call_that_would_drop_columns_whose_runs_are_gone_stops_before_running(self):
        def summary(quick):
            rows = [["4", "500", "1"], ["4", "1300", "1"], ["4", "1300", "2"]]
            with open(os.path.join(tmp, fm.model.name + ".json"), "w") as f:
                json.dump({"quick": quick, "tables": [{"header": ["gate [cm]", "crosses",
                                                                  "seed"], "rows": rows}]}, f)

        started = []
        argv = ["--element-contacts", "mean", "--depth-cm", "20", "--seeds", "1", "2"]
        with tempfile.TemporaryDirectory() as tmp, mock.patch.object(fm, "RESULTS", tmp), \
                mock.patch.multiple(fm, finished_columns=lambda seeds: [],
                                    unfinished=lambda run: "not run",
                                    run_all=lambda exe, cols, seeds: started.append(cols)):
            fm.model = fm.MEAN.in_experiments_box()
            self.assertEqual(fm.columns_in_summary(), [])  # none on disk
            summary(False)
            self.assertEqual(fm.columns_in_summary(), [(4, 500), (4, 1300)])
            self.assertEqual(fm.dropped_columns([(4, 1300), (8, 1000)]), [(4, 500)])
            with self.assertRaises(SystemExit) as stop:
                fm.main(argv + ["--columns", "8:1000"])
            self.assertIn("crosses_flow_map_mean_deep.json holds columns whose runs are not "
                          "on disk and that this call does not run: 4:500 4:1300",
                          str(stop.exception.code))
            self.assertEqual(started, [])  # stopped before running
            for extra in (["--columns", "4:500", "4:1300", "8:1000"],  # runs them again
                          ["--columns", "8:1000", "--drop-missing"]):
                with self.assertRaises(SystemExit) as stop:  # the mocked runs never finish
                    fm.main(argv + extra)
                self.assertIn("not mapped", str(stop.exception.code))
            self.assertEqual(len(started), 2)
            summary(True)  # a quick summary holds no columns to keep
            self.assertEqual(fm.columns_in_summary(), [])
        fm.model = fm.SUM
        fm.depth_m = fm.DEPTH_M

    def test_the_map_reports_every_column_finished_on_disk(self):
        with tempfile.TemporaryDirectory() as tmp, mock.patch.object(fm, "RESULTS", tmp):
            fm.model = fm.MEAN_POINT.in_experiments_box()
            for name in ("L4cm_500", "L4cm_1300", "L8cm_1000", "L2.5cm_100", "points", "map"):
                for seed in (1, 2, 3):
                    os.makedirs(os.path.join(fm.model.runs(), name, f"seed_{seed}"))
            unfinished = {fm.folder(8, 1000, 3)}  # its seed 3 still running
            with mock.patch.object(fm, "unfinished",
                                   lambda run: "not run" if run in unfinished else None):
                self.assertEqual(fm.finished_columns([1, 2, 3]),
                                 [(2.5, 100), (4, 1300), (4, 500)])
                self.assertEqual(fm.finished_columns([1, 2]),
                                 [(2.5, 100), (4, 1300), (4, 500), (8, 1000)])
        fm.model = fm.SUM

    def test_the_columns_of_most_crosses_run_first_each_over_every_seed(self):
        self.assertEqual(fm.in_run_order([(4, 150), (8, 600), (4, 300)], [1, 2]),
                         [(8, 600, 1), (8, 600, 2), (4, 300, 1), (4, 300, 2), (4, 150, 1),
                          (4, 150, 2)])

    def test_only_finished_runs_are_mapped(self):
        with tempfile.TemporaryDirectory() as tmp:
            self.assertEqual(fm.unfinished(os.path.join(tmp, "absent")), "not run")
            fake_run(os.path.join(tmp, "pouring"), 1e6, 1.2, False)
            self.assertEqual(fm.unfinished(os.path.join(tmp, "pouring")), "stopped in the pour")
            fake_run(os.path.join(tmp, "collapsing"), 2.0, 3.1, False)
            self.assertIn("stopped in the collapse at 3.1 s",
                          fm.unfinished(os.path.join(tmp, "collapsing")))
            fake_run(os.path.join(tmp, "at_rest"), 2.0, 3.6, True)
            self.assertIsNone(fm.unfinished(os.path.join(tmp, "at_rest")))
            fake_run(os.path.join(tmp, "full"), 2.0, 2.0 + db.COLLAPSE_S, False)
            self.assertIsNone(fm.unfinished(os.path.join(tmp, "full")))


class Outcomes(unittest.TestCase):
    def test_a_repeatable_column_names_its_regime_an_intermittent_one_its_counts(self):
        self.assertEqual(fm.outcome_text({"outcome": "collapsed", "collapsed": "3",
                                          "fractured": "0", "stable": "0"}),
                         "collapsed (repeatable)")
        self.assertEqual(fm.outcome_text({"outcome": "intermittent", "collapsed": "1",
                                          "fractured": "0", "stable": "2"}),
                         "intermittent: 1 collapsed, 2 stable")

    def test_a_map_needs_two_packings_per_column(self):
        with self.assertRaises(SystemExit):
            fm.main(["--seeds", "1", "--reuse"])


if __name__ == "__main__":
    unittest.main()
