#!/usr/bin/python3
"""rostest sim_time_warning: with /use_sim_time false cart_sim says so (ROS_WARN naming the
parameter) and still runs; with ~follow_clock it refuses to start (exit 2, ROS_FATAL)."""
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
                           "_fast:=true", "_duration:=0.1"] + list(arguments),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                          timeout=RUN_LIMIT, stdin=subprocess.DEVNULL)


class SimTimeWarning(unittest.TestCase):
    def test_warns_and_runs(self):
        result = cart_sim("warning_sim")
        self.assertEqual(result.returncode, 0, result.stdout)
        self.assertIn("/use_sim_time is false", result.stdout)
        self.assertIn("cart_sim summary: finished", result.stdout)
        result.stdout.encode("ascii")  # every log line, the summary included, is plain ASCII

    def test_refuses_to_follow_a_clock_that_is_not_used(self):
        result = cart_sim("follower_sim", "_publish_clock:=false", "_follow_clock:=true")
        self.assertEqual(result.returncode, 2, result.stdout)
        self.assertIn("~follow_clock is true but /use_sim_time is false", result.stdout)

    def test_log_lines_are_ascii(self):
        result = cart_sim("bad_torque_sim", "_max_steering_torque:=-1")
        self.assertEqual(result.returncode, 2, result.stdout)
        self.assertIn("must be > 0 N m", result.stdout)
        result.stdout.encode("ascii")  # raises on "N·m" and the like


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "sim_time_warning", SimTimeWarning, sys.argv)
