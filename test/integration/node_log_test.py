#!/usr/bin/python3
"""rostest node_log: with /use_sim_time false cart_sim says so (ROS_WARN naming the parameter) and
still runs; a misspelled private parameter is named with the closest one it reads; with ~follow_clock it refuses to start (exit 2, ROS_FATAL); its log is ASCII; a fast
run longer than a second of wall time logs progress lines (scene time, percent, real-time factor)."""
import re
import os
import subprocess
import sys
import unittest

import rospkg
import rostest

PACKAGE = "birkhoff_cart"
RUN_LIMIT = 30  # [s of wall time], only against hangs


def cart_sim(name, *arguments):
    """cart_sim under its own `name`: _param:=value arguments stay on the master, so no run may
    inherit another's."""
    scene = os.path.join(rospkg.RosPack().get_path(PACKAGE), "config", "scenes", "free_coast.yaml")
    return subprocess.run(["rosrun", PACKAGE, "cart_sim", "__name:=" + name, "_scene:=" + scene,
                           "_fast:=true"] + list(arguments),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                          timeout=RUN_LIMIT, stdin=subprocess.DEVNULL)


class NodeLog(unittest.TestCase):
    def test_warns_and_runs(self):
        result = cart_sim("warning_sim", "_duration:=0.1")
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assertIn("/use_sim_time is false", result.stdout)
        self.assertIn("cart_sim summary: finished", result.stdout)
        result.stdout.encode("ascii")  # every log line, the summary included, is plain ASCII

    def test_refuses_to_follow_a_clock_that_is_not_used(self):
        result = cart_sim("follower_sim", "_duration:=0.1", "_publish_clock:=false", "_follow_clock:=true")
        self.assertEqual(result.returncode, 2, result.stdout)
        self.assertIn("~follow_clock is true but /use_sim_time is false", result.stdout)

    def test_log_lines_are_ascii(self):
        result = cart_sim("bad_torque_sim", "_duration:=0.1", "_max_steering_torque:=-1")
        self.assertEqual(result.returncode, 2, result.stdout)
        self.assertIn("must be > 0 N m", result.stdout)
        result.stdout.encode("ascii")  # raises on "N·m" and the like


    def test_names_the_closest_parameter_for_a_typo(self):
        result = cart_sim("typo_sim", "_duration:=0.1", "_publsh_rate:=50")
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assertIn("parameter /typo_sim/publsh_rate is not one of this node's and is ignored "
                      "(did you mean /typo_sim/publish_rate?)", result.stdout)

    def test_reports_progress_in_a_long_fast_run(self):
        # 3 s of scene time paced at twice real time: ~1.5 s of wall time, so at least one line.
        result = cart_sim("progress_sim", "_duration:=3.0", "_real_time_factor:=2.0")
        self.assertEqual(result.returncode, 0, result.stdout)
        lines = re.findall(r"cart_sim: t = ([0-9.]+) s of 3\.000 s \(([0-9.]+) %\), real-time factor ([0-9.]+)",
                           result.stdout)
        self.assertTrue(lines, result.stdout)
        for time, percent, factor in lines:
            self.assertAlmostEqual(float(percent), 100.0 * float(time) / 3.0, delta=0.1)
            self.assertGreater(float(factor), 0.0)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "node_log", NodeLog, sys.argv)
