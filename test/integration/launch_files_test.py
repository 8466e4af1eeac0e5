#!/usr/bin/python3
"""rostest launch_files: each shipped launch file that starts cart_sim sets PINNED on every
cart_sim it starts (roslaunch --dump-params), and the default bag paths of sim.launch and
paper.launch lie under $ROS_HOME when it is set; lockstep.launch runs its loop as nodelets and as
nodes and ends with the run."""
import glob
import os
import subprocess
import unittest

import rospkg
import rostest
import yaml

PACKAGE = "birkhoff_cart"
# How cart_sim runs (pace, lockstep, clock, pause, end) and where its data goes.
PINNED = ["fast", "real_time_factor", "lockstep", "duration", "publish_clock", "follow_clock", "start_paused",
          "bag_path"]


def dumped_parameters(launch, ros_home):
    environment = dict(os.environ, ROS_HOME=ros_home)
    result = subprocess.run(["roslaunch", "--dump-params", PACKAGE, os.path.basename(launch)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                            env=environment, timeout=60, stdin=subprocess.DEVNULL)
    if result.returncode != 0:
        raise AssertionError("roslaunch --dump-params %s failed:\n%s" % (launch, result.stdout))
    return yaml.safe_load(result.stdout)


class LaunchFiles(unittest.TestCase):
    def setUp(self):
        self.launch_directory = os.path.join(rospkg.RosPack().get_path(PACKAGE), "launch")
        self.ros_home = "/tmp/birkhoff_cart_ros_home_%d" % os.getpid()

    def test_every_cart_sim_has_its_run_parameters_pinned(self):
        checked = 0
        for launch in sorted(glob.glob(os.path.join(self.launch_directory, "*.launch"))):
            if 'type="cart_sim"' not in open(launch).read():
                continue
            parameters = dumped_parameters(launch, self.ros_home)
            nodes = sorted(key[:-len("scene")] for key in parameters if key.endswith("/cart_sim/scene"))
            self.assertTrue(nodes, "%s starts cart_sim but sets no scene" % launch)
            for node in nodes:
                missing = [name for name in PINNED if node + name not in parameters]
                self.assertEqual(missing, [], "%s leaves %s to whatever the master holds for %s" %
                                 (os.path.basename(launch), ", ".join("~" + m for m in missing), node + "*"))
                # Only lockstep.launch runs its loop in lockstep.
                lockstep = os.path.basename(launch) == "lockstep.launch"
                self.assertIs(parameters[node + "lockstep"], lockstep, "%s %s" % (launch, node))
                checked += 1
        self.assertGreaterEqual(checked, 6)  # sim, cmd_vel, driven, lockstep, paper, two carts (x2)

    def test_default_bags_go_under_ros_home(self):
        sim = dumped_parameters(os.path.join(self.launch_directory, "sim.launch"), self.ros_home)
        self.assertEqual(sim["/cart_sim/bag_path"], self.ros_home + "/birkhoff_cart.bag")
        paper = dumped_parameters(os.path.join(self.launch_directory, "paper.launch"), self.ros_home)
        paths = [value for key, value in paper.items() if key.endswith("/cart_sim/bag_path")]
        self.assertTrue(paths)
        for path in paths:
            self.assertTrue(path.startswith(self.ros_home + "/paper_"), path)

    def test_lockstep_launch_runs_the_loop_and_ends_with_it(self):
        # Both ways: nodelets in one manager (cart_sim's ~end_launch from inside the manager) and two
        # node processes; each ends by itself with every instant answered.
        for nodelets in ("true", "false"):
            summary = "/tmp/birkhoff_cart_lockstep_%d_%s.summary" % (os.getpid(), nodelets)
            result = subprocess.run(["roslaunch", PACKAGE, "lockstep.launch", "nodelets:=" + nodelets, "duration:=2",
                                     "summary_path:=" + summary], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                    universal_newlines=True, timeout=60, stdin=subprocess.DEVNULL)
            self.assertEqual(result.returncode, 0, result.stdout[-3000:])
            self.assertNotIn("REQUIRED process", result.stdout)
            with open(summary) as file:
                text = file.read()
            os.remove(summary)
            self.assertIn("final t = 2 s", text)
            self.assertIn("Lockstep timeouts: 0.", text)
            self.assertIn("Published instants: 100.", text)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "launch_files", LaunchFiles)
