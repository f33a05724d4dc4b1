"""Tests of validation/dem/_outputs.py, the readers and run-folder helpers every DEM
validation script relies on. Run by ctest (ValidationScripts.DemHelpers) or by hand:
/usr/bin/python3 -m unittest discover -s validation/dem -p 'test_*.py'"""
import argparse
import base64
import contextlib
import functools
import io
import json
import os
import shutil
import struct
import sys
import tempfile
import threading
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _outputs  # noqa: E402


def data_array(name, kind, values, components=1):
    """A VTK XML DataArray in sanguis' binary form: base64 of a UInt64 byte count, then
    the little-endian values."""
    fmt = {"Float64": "d", "Int64": "q", "UInt8": "B"}[kind]
    raw = struct.pack(f"<{len(values)}{fmt}", *values)
    payload = base64.b64encode(struct.pack("<Q", len(raw)) + raw).decode()
    return (f'<DataArray type="{kind}" Name="{name}" NumberOfComponents="{components}" '
            f'format="binary">\n  {payload}\n</DataArray>')


def write_text(folder, name, text):
    """Writes folder/name and returns its path."""
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def write_run_log(folder, lines):
    os.makedirs(folder, exist_ok=True)
    write_text(folder, "run.log", "\n".join(lines) + "\n")


class ContactModel(unittest.TestCase):
    def parse(self, argv):
        ap = argparse.ArgumentParser()
        _outputs.add_contact_model_options(ap, "case", "with Table 3.1")
        return _outputs.contact_model(ap, ap.parse_args(argv))

    def test_the_options_give_the_model_its_name_and_overrides(self):
        self.assertEqual(self.parse([]), (False, False))
        self.assertEqual(self.parse(["--element-contacts", "mean"]), (True, False))
        self.assertEqual(self.parse(["--element-contacts", "mean", "--flat-contacts", "point"]),
                         (True, True))
        self.assertEqual(_outputs.contact_model_suffix(False, False), "")
        self.assertEqual(_outputs.contact_model_suffix(True, False), "_mean")
        self.assertEqual(_outputs.contact_model_suffix(True, True), "_mean_point")
        self.assertEqual(_outputs.contact_model_settings(False, False), [])
        self.assertEqual(_outputs.contact_model_settings(True, True),
                         ["--set", 'simulation.element_contacts="mean"',
                          "--set", 'simulation.flat_contacts="point"'])

    def test_one_point_without_the_mean_is_refused_with_exit_2(self):
        err = io.StringIO()
        with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as raised:
            self.parse(["--flat-contacts", "point"])
        self.assertEqual(raised.exception.code, 2)
        self.assertIn("--flat-contacts point runs with --element-contacts mean", err.getvalue())


class ReadArrays(unittest.TestCase):
    def test_reads_float_and_integer_arrays_and_skips_other_types(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = write_text(tmp, "frame.vtu",
                              "<VTKFile><UnstructuredGrid><Piece><PointData>\n"
                              + data_array("velocity", "Float64", [1, 2, 3, -4.0, 5.5, 6], 3)
                              + "\n" + data_array("id", "Int64", [7, -8]) + "\n"
                              + data_array("flags", "UInt8", [1, 0]) + "\n"
                              + "</PointData><Points>\n"
                              + data_array("Points", "Float64", [0.0] * 6, 3)
                              + "\n</Points></Piece></UnstructuredGrid></VTKFile>\n")
            arrays = _outputs.read_arrays(path)
        self.assertEqual(sorted(arrays), ["Points", "id", "velocity"])
        self.assertEqual(arrays["velocity"].shape, (2, 3))
        self.assertEqual(arrays["velocity"][1].tolist(), [-4.0, 5.5, 6.0])
        self.assertEqual(arrays["id"].tolist(), [7, -8])


class ReadPvd(unittest.TestCase):
    def test_gives_times_and_absolute_paths_in_order(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = write_text(tmp, "particles.pvd",
                              '<VTKFile type="Collection"><Collection>'
                              '<DataSet timestep="0" file="frames/p_0.vtu"/>'
                              '<DataSet timestep="0.25" file="frames/p_1.vtu"/>'
                              '</Collection></VTKFile>')
            frames = _outputs.read_pvd(path)
            self.assertEqual(frames, [(0.0, os.path.join(tmp, "frames/p_0.vtu")),
                                      (0.25, os.path.join(tmp, "frames/p_1.vtu"))])


class CaseAndSummaries(unittest.TestCase):
    def test_gate_removal_time_comes_from_the_obstacle_named_gate(self):
        with tempfile.TemporaryDirectory() as tmp:
            case = write_text(tmp, "case.toml", '[[obstacle]]\nname = "floor"\n\n'
                              '[[obstacle]]\nname = "gate"\nremove_at_s = 2.4\n')
            self.assertEqual(_outputs.gate_removal_time(case), 2.4)
            write_text(tmp, "case.toml", '[[obstacle]]\nname = "floor"\n')
            with self.assertRaisesRegex(ValueError, "no obstacle named 'gate'"):
                _outputs.gate_removal_time(case)

    def test_summary_row_and_regime(self):
        with tempfile.TemporaryDirectory() as tmp:
            os.makedirs(os.path.join(tmp, "analysis"))
            write_text(os.path.join(tmp, "analysis"), "summary.csv", "runout_m,regime\n0.125,1\n")
            summary = _outputs.read_summary(tmp)
        self.assertEqual(summary, {"runout_m": 0.125, "regime": 1.0})
        self.assertEqual(_outputs.regime_name(summary), "fractured")
        self.assertEqual(_outputs.regime_name({"regime": 0.0}), "stable")
        self.assertEqual(_outputs.regime_name({"regime": 2.0}), "collapsed")

    def test_calibration_folder_is_found_by_value_not_by_spelling(self):
        with tempfile.TemporaryDirectory() as tmp:
            for name in ("value_0.1", "value_1e-05", "value_300"):
                os.makedirs(os.path.join(tmp, name))
            self.assertEqual(_outputs.calibration_value_folder(tmp, 1e-5),
                             os.path.join(tmp, "value_1e-05"))
            self.assertEqual(_outputs.calibration_value_folder(tmp, 300.0),
                             os.path.join(tmp, "value_300"))
            with self.assertRaises(FileNotFoundError):
                _outputs.calibration_value_folder(tmp, 0.2)

    def test_write_summary_completes_and_writes_the_case_file(self):
        with tempfile.TemporaryDirectory() as tmp:
            _outputs.write_summary({"name": "case_x", "checks": []}, tmp, 12.345, False, True)
            with open(os.path.join(tmp, "case_x.json")) as f:
                s = json.load(f)
        self.assertEqual(s["run_time_s"], 12.3)
        self.assertIs(s["quick"], False)
        self.assertIs(s["pass"], True)
        self.assertRegex(s["date"], r"^\d{4}-\d\d-\d\d \d\d:\d\d$")


# A run.log as written since 2026-12-05, every line stamped in UTC: a segment to 5 s, one
# killed after its checkpoint at 5.25 s, and one to 6.1 s.
STAMPED_LOG = [
    "sanguis 0.1.0, started 2026-12-05 19:15:02 UTC",
    "done: t = 5 s, 2000000 steps in 1h56m (2.92e+05 particle-steps/s), ended "
    "2026-12-05 21:11:40 UTC",
    "--- restart from checkpoint at t = 5.000000 s, 2026-12-05 21:20:00 UTC",
    "checkpoint: t = 5.25 s, 100000 steps in 10m00s, 2026-12-05 21:30:00 UTC",
    "--- restart from checkpoint at t = 5.250000 s, 2026-12-05 22:00:00 UTC",
    "done: t = 6.1 s, 240000 steps in 22m00s (1e+05 particle-steps/s), ended "
    "2026-12-05 22:22:00 UTC, settled"]


class RunSegments(unittest.TestCase):
    LOG = ["sanguis 0.1, case.toml",
           "done: t = 3 s, 880000 steps in 11m25s (2.964e+05 particle-steps/s)",
           "restart from checkpoint.bin at t = 3 s",
           "done: t = 3.8 s, 320000 steps in 1h05m (2.779e+05 particle-steps/s), settled",
           "done: t = 4 s, 10 steps in 7s (1e+05 particle-steps/s)"]

    def test_each_done_line_is_a_segment_with_its_wall_time(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_run_log(tmp, self.LOG)
            self.assertEqual(list(_outputs.finished_segments(tmp)),
                             [(3.0, 685), (3.8, 3900), (4.0, 7)])
            self.assertEqual(_outputs.reached_time(tmp), 4.0)
            self.assertEqual(_outputs.wall_time(tmp), 685 + 3900 + 7)
            self.assertEqual(_outputs.wall_time(tmp, after=3.0), 3900 + 7)

    def test_a_stopped_segment_counts_to_its_last_checkpoint(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_run_log(tmp, [
                "done: t = 5 s, 2000000 steps in 1h56m (2.92e+05 particle-steps/s)",
                "--- restart from checkpoint at t = 5.000000 s",
                "checkpoint: t = 5.25 s, 100000 steps in 10m00s",
                "checkpoint: t = 5.5 s, 200000 steps in 20m05s",
                "--- restart from checkpoint at t = 5.500000 s",  # the call was killed
                "checkpoint: t = 5.75 s, 100000 steps in 9m30s",
                "done: t = 6.1 s, 240000 steps in 22m00s (1e+05 particle-steps/s), settled",
                "--- restart from checkpoint at t = 6.100000 s",
                "checkpoint: t = 6.35 s, 100000 steps in 11m00s"])  # running, or killed
            self.assertEqual(list(_outputs.finished_segments(tmp)),
                             [(5.0, 6960), (5.5, 1205), (6.1, 1320), (6.35, 660)])
            self.assertEqual(_outputs.reached_time(tmp), 6.35)
            self.assertEqual(_outputs.wall_time(tmp, after=5.0), 1205 + 1320 + 660)
            self.assertEqual(_outputs.done_times(tmp), [5.0, 6.1])

    def test_lines_stamped_with_the_date_read_the_same(self):
        # Since 2026-12-05 run.log stamps its start, restarts, checkpoints and end in UTC.
        with tempfile.TemporaryDirectory() as tmp:
            write_run_log(tmp, STAMPED_LOG)
            self.assertEqual(list(_outputs.finished_segments(tmp)),
                             [(5.0, 6960), (5.25, 600), (6.1, 1320)])
            self.assertEqual(_outputs.done_times(tmp), [5.0, 6.1])
            self.assertEqual(_outputs.uncounted_spans(tmp), [])

    def test_a_span_run_before_checkpoint_lines_is_named_as_not_counted(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_run_log(tmp, [
                "done: t = 5 s, 2000000 steps in 1h56m (2.92e+05 particle-steps/s)",
                "--- restart from checkpoint at t = 5.000000 s",  # killed, no lines
                "--- restart from checkpoint at t = 6.750000 s",
                "checkpoint: t = 7 s, 100000 steps in 10m00s",
                "--- restart from checkpoint at t = 7.000000 s",  # killed after a line
                "done: t = 8 s, 400000 steps in 40m00s (1e+05 particle-steps/s)"])
            self.assertEqual(_outputs.uncounted_spans(tmp), [(5.0, 6.75)])
            self.assertEqual(_outputs.wall_time(tmp, after=5.0), 600 + 2400)
            write_run_log(tmp, self.LOG)
            self.assertEqual(_outputs.uncounted_spans(tmp), [])

    def test_a_folder_without_log_has_no_segments(self):
        with tempfile.TemporaryDirectory() as tmp:
            self.assertEqual(list(_outputs.finished_segments(tmp)), [])
            self.assertEqual(_outputs.reached_time(tmp), 0.0)
            self.assertEqual(_outputs.wall_time(tmp), 0)


class SegmentStarts(unittest.TestCase):
    def test_the_start_and_restart_lines_give_when_segments_began(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_run_log(tmp, [
                "sanguis 0.1.0, started 2026-12-05 21:56:08 UTC",
                "checkpoint: t = 0.05 s, 20000 steps in 3m40s, 2026-12-05 21:59:48 UTC",
                "",
                "--- restart from checkpoint at t = 4.850000 s",
                "--- restart from checkpoint at t = 4.900000 s, 2026-12-05 23:10:00 UTC"])
            starts = _outputs.segment_starts(tmp)
            self.assertEqual(starts, ["2026-12-05 21:56:08", None, "2026-12-05 23:10:00"])
            self.assertEqual([t >= _outputs.TWIST_MOMENT_FROM for t in starts if t],
                             [False, True])
            self.assertEqual(_outputs.segment_starts(os.path.join(tmp, "none")), [])


class Stops(unittest.TestCase):
    # STAMPED_LOG's counted segments: 19:15:00-21:11:40 (to 5 s), 21:20:00-21:30:00 (to
    # 5.25 s, then killed; the time after lost) and 22:00:00-22:22:00.
    def test_the_stops_that_fall_in_counted_segments_are_what_their_wall_times_hold(self):
        with tempfile.TemporaryDirectory() as d:
            self.assertEqual(_outputs.stops(d), [])
            write_run_log(d, STAMPED_LOG)
            write_text(d, "PAUSES.txt",
                       "2026-12-05T21:00 stopped for the CI of abc (5.0 min)\n"      # inside
                       "2026-12-05T21:10:40-21:12:40 stopped for a build (2.0 min)\n"  # 1 of 2
                       "2026-12-05T21:35 stopped for the CI of def (5.5 min)\n"       # lost time
                       "2026-12-05T21:40 the session ended; restarted at 22:00\n"      # no length
                       "2026-12-05T22:10 stopped for benchmarks (3 min)\n")           # inside
            stop_list = _outputs.stops(d)
            self.assertEqual(len(stop_list), 4)
            intervals = _outputs.counted_intervals(d)
            self.assertEqual([round(b - a) for a, b in intervals], [6960, 600, 1320])
            self.assertAlmostEqual(_outputs.stopped_seconds(intervals, stop_list),
                                   300 + 60 + 180)
            # after 5 s: the segments of the collapse alone, which the 21:00 stop is not in
            self.assertAlmostEqual(_outputs.stopped_seconds(
                _outputs.counted_intervals(d, after=5.0), stop_list), 180)
            self.assertEqual(_outputs.runs_utc(intervals), ["2026-12-05 19:15", "2026-12-05 22:22"])
            self.assertIsNone(_outputs.runs_utc([]))
            # two runs stopped at once: their union holds each stop once
            self.assertAlmostEqual(_outputs.stopped_seconds(intervals + intervals, stop_list),
                                   540)

    def test_a_stop_without_a_date_cannot_be_placed_and_is_refused(self):
        with tempfile.TemporaryDirectory() as d:
            path = write_text(d, "PAUSES.txt", "- pour (stop 49): about 17 min (CI)\n")
            with self.assertRaises(SystemExit) as stop:
                _outputs.stops(d)
            self.assertIn(f"{path}:1: a stop of 17 min without a date", str(stop.exception))


class TwoAtATime(unittest.TestCase):
    def test_span_of_jobs_run_two_at_a_time_oldest_first(self):
        self.assertEqual(_outputs.two_at_a_time_span([]), 0.0)
        self.assertEqual(_outputs.two_at_a_time_span([5.0]), 5.0)
        # The third starts when the first ends (the runner waits on the older job).
        self.assertEqual(_outputs.two_at_a_time_span([783, 823, 665]), 783 + 665)
        # ... even when the second ended sooner.
        self.assertEqual(_outputs.two_at_a_time_span([10, 2, 1]), 11)
        self.assertEqual(_outputs.two_at_a_time_span([1, 1, 1, 1]), 2)


class CallTwoAtATime(unittest.TestCase):
    def test_every_call_runs_never_more_than_two_at_once(self):
        lock, running, most, done = threading.Lock(), [0], [0], []

        def call(k):
            with lock:
                running[0] += 1
                most[0] = max(most[0], running[0])
            time.sleep(0.02)
            with lock:
                running[0] -= 1
                done.append(k)
        _outputs.call_two_at_a_time([functools.partial(call, k) for k in range(5)])
        self.assertEqual(sorted(done), list(range(5)))
        self.assertEqual(most[0], 2)

    def test_a_failure_cancels_the_calls_not_started_and_is_raised(self):
        started, finished = [], []

        def call(k):
            started.append(k)
            time.sleep(0.0 if k == 0 else 0.05)
            if k == 0:
                raise RuntimeError("run failed")
            finished.append(k)
        with self.assertRaisesRegex(RuntimeError, "run failed"):
            _outputs.call_two_at_a_time([functools.partial(call, k) for k in range(6)])
        self.assertIn(1, finished)  # the one running beside the failure ran to its end
        self.assertLess(len(started), 6)


class PoolSpan(unittest.TestCase):
    def test_a_pool_starts_each_job_when_any_worker_is_free(self):
        self.assertEqual(_outputs.pool_span([10, 2, 1]), 10)  # two at a time, oldest first: 11
        self.assertEqual(_outputs.pool_span([1, 2, 3, 4]), 6)
        self.assertEqual(_outputs.pool_span([5]), 5)
        self.assertEqual(_outputs.pool_span([3, 3, 3], workers=3), 3)


class SpeedLandmarks(unittest.TestCase):
    def test_peak_its_time_and_the_last_stop_under_the_line(self):
        t = [0, 1, 2, 3, 4, 5, 6, 7]
        landmarks = _outputs.speed_landmarks
        self.assertEqual(landmarks(t, [0, 0.3, 0.1, 0.04, 0.01, 0, 0, 0]), (0.3, 1, 3))
        # A halt and a restart (Fig. 3.10): the collapse ends at its last stop.
        self.assertEqual(landmarks(t, [0, 0.3, 0.01, 0.01, 0.2, 0.01, 0, 0]), (0.3, 1, 5))
        # Still moving at the end; never above the line.
        self.assertEqual(landmarks(t, [0, 0.3, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1])[2], float("inf"))
        self.assertEqual(landmarks(t, [0, 0.01, 0.02, 0.01, 0, 0, 0, 0]), (0.02, 2, 2))


class PourCommand(unittest.TestCase):
    CMD = ["sanguis", "run", "case.toml", "-o", "pour"]

    def pour(self, tmp, log, checkpoint=True):
        out = os.path.join(tmp, "pour")
        write_run_log(out, log)
        if checkpoint:
            open(os.path.join(out, "checkpoint.bin"), "w").close()
        return out

    def test_a_pour_that_reached_its_end_is_kept(self):
        # An end time of more than four digits too (run.log gives ten).
        for end in ("2.4", "2.40625"):
            with tempfile.TemporaryDirectory() as tmp:
                out = self.pour(tmp, [f"done: t = {end} s, 10 steps in 5s (1 particle-steps/s)"])
                self.assertIsNone(_outputs.pour_command(self.CMD, out, float(end)), end)

    def test_a_stopped_pour_is_continued_from_its_checkpoint(self):
        with tempfile.TemporaryDirectory() as tmp:
            # A killed run: its last segment wrote no done line; its checkpoint is from
            # an earlier time than the opening.
            out = self.pour(tmp, ["done: t = 0.8 s, 10 steps in 5s (1 particle-steps/s)"])
            self.assertEqual(_outputs.pour_command(self.CMD, out, 2.4),
                             self.CMD + ["--restart", "--set", "simulation.end_time_s=2.4"])

    def test_an_empty_folder_gets_a_fresh_run(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "pour")
            self.assertEqual(_outputs.pour_command(self.CMD, out, 2.4),
                             self.CMD + ["--set", "simulation.end_time_s=2.4"])

    def test_run_pour_runs_the_command_only_when_one_is_needed(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = self.pour(tmp, ["done: t = 2.4 s, 10 steps in 5s (1 particle-steps/s)"])
            self.assertFalse(_outputs.run_pour(["false"], out, 2.4))  # `false` would raise
            self.assertTrue(_outputs.run_pour(["true"], out, 3.0))

    def test_rerun_clears_a_finished_pour(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = self.pour(tmp, ["done: t = 2.4 s, 10 steps in 5s (1 particle-steps/s)"])
            self.assertEqual(_outputs.pour_command(self.CMD, out, 2.4, rerun=True),
                             self.CMD + ["--set", "simulation.end_time_s=2.4"])
            self.assertFalse(os.path.exists(out))


class Continuation(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp()
        self.pour = os.path.join(self.tmp, "pour")
        write_run_log(self.pour, ["done: t = 5 s, 10 steps in 5s (1 particle-steps/s)"])
        open(os.path.join(self.pour, "checkpoint.bin"), "w").close()
        self.out = os.path.join(self.tmp, "collapse")
        self.cmd = ["/any/build/sanguis", "run", "case.toml", "--output", self.out, "--restart",
                    "--set", "a=1"]

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def log_of_out(self):
        with open(os.path.join(self.out, "run.log")) as f:
            return f.read()

    def test_the_record_leaves_out_the_program_and_the_output_folder(self):
        self.assertEqual(_outputs.command_record(self.cmd), "run case.toml --restart --set a=1")
        self.assertEqual(_outputs.command_record(["x", "run", "-o", "y", "c.toml"]), "run c.toml")

    def test_a_new_continuation_starts_as_a_copy_of_the_pour(self):
        self.assertEqual(_outputs.continuation_command(self.cmd, self.out, self.pour, 5.0),
                         self.cmd)
        self.assertIn("t = 5 s", self.log_of_out())
        with open(os.path.join(self.out, "continuation.txt")) as f:
            self.assertEqual(f.read(), "run case.toml --restart --set a=1\n")

    def test_a_stopped_continuation_goes_on_and_a_finished_one_is_kept(self):
        _outputs.continuation_command(self.cmd, self.out, self.pour, 5.0)
        with open(os.path.join(self.out, "run.log"), "a") as f:
            f.write("--- restart from checkpoint at t = 5.000000 s\n"
                    "checkpoint: t = 5.25 s, 10 steps in 5s\n")
        # Stopped: the same command, nothing copied over the folder.
        self.assertEqual(_outputs.continuation_command(self.cmd, self.out, self.pour, 5.0),
                         self.cmd)
        self.assertIn("t = 5.25 s", self.log_of_out())
        with open(os.path.join(self.out, "run.log"), "a") as f:
            f.write("done: t = 6.5 s, 10 steps in 5s (1 particle-steps/s), settled\n")
        self.assertIsNone(_outputs.continuation_command(self.cmd, self.out, self.pour, 5.0))
        # Another command (other settings, not the folder or program): a fresh copy.
        other = self.cmd[:-1] + ["a=2"]
        self.assertEqual(_outputs.continuation_command(other, self.out, self.pour, 5.0), other)
        self.assertNotIn("t = 5.25 s", self.log_of_out())
        with open(os.path.join(self.out, "run.log"), "a") as f:
            f.write("checkpoint: t = 5.5 s, 10 steps in 5s\n")
        # The same settings from another build, with the folder named otherwise: goes on.
        moved = ["sanguis", "run", "case.toml", "-o", "elsewhere", "--restart", "--set", "a=2"]
        self.assertEqual(_outputs.continuation_command(moved, self.out, self.pour, 5.0), moved)
        self.assertIn("t = 5.5 s", self.log_of_out())


class Span(unittest.TestCase):
    def test_a_range_of_positive_values_takes_a_dash(self):
        self.assertEqual(_outputs.span([2.5, 0.98, 16.34], ".2f"), "0.98-16.34")

    def test_a_range_from_a_negative_value_is_written_out(self):
        self.assertEqual(_outputs.span([-0.15, 2.48, 0.11], ".2f"), "-0.15 to 2.48")

    def test_values_that_print_alike_give_one(self):
        self.assertEqual(_outputs.span([3.001, 3.004], ".1f"), "3.0")
        self.assertEqual(_outputs.span([7], "d"), "7")


if __name__ == "__main__":
    unittest.main()
