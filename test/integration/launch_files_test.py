#!/usr/bin/python3
"""rostest launch_files: each shipped launch file that starts cart_sim sets PINNED on every
cart_sim it starts (roslaunch --dump-params), and the default bag paths of sim.launch and
paper.launch lie under $ROS_HOME when it is set; every node of birkhoff_cart that a launch file
starts clears its private parameters first (clear_params), so that a parameter an earlier run left
on the master, a typo included, changes nothing; lockstep.launch runs its loop as nodelets and as
nodes and ends with the run."""
import glob
import os
import subprocess
import unittest

import roslaunch.config
import rospkg
import rospy
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

    def test_every_node_of_the_package_clears_its_private_parameters(self):
        checked = 0
        for launch in sorted(glob.glob(os.path.join(self.launch_directory, "*.launch"))):
            text = open(launch).read()
            if os.path.basename(launch) == "replay.launch":
                continue  # rosbag, robot_state_publisher and rviz only
            # Every optional node started (rviz, cmd_vel), so that every node is seen; lockstep.launch
            # both ways.
            variants = [[a for a in ("rviz:=true", "cmd_vel:=true") if ("name=\"%s\"" % a.split(":=")[0]) in text]]
            if 'name="nodelets"' in text:
                variants = [["nodelets:=true"], ["nodelets:=false"]]
            for arguments in variants:
                config = roslaunch.config.load_config_default([(launch, arguments)], None, verbose=False)
                cleared = set(config.clear_params)
                for node in config.nodes:
                    if node.package != PACKAGE and "load birkhoff_cart/" not in node.args:
                        continue
                    namespace = (node.namespace + node.name + "/").replace("//", "/")
                    self.assertIn(namespace, cleared, "%s %s starts %s without clear_params: parameters an earlier "
                                  "run left under %s would change it" %
                                  (os.path.basename(launch), " ".join(arguments), node.type, namespace))
                    checked += 1
        # sim and cmd_vel (cart_sim, cmd_vel_controller each), driven (cart_sim, steering_driver),
        # lockstep (two nodelets; two nodes), paper (one cart per integrator), two_carts (three).
        self.assertGreaterEqual(checked, 14)

    def test_a_stale_lockstep_and_a_typo_on_the_master_change_nothing(self):
        # The README's own rosrun example leaves ~lockstep true; with it driven.launch would wait for a
        # controller forever. A misspelled parameter would be named as a typo at every later launch.
        rospy.set_param("/cart_sim/lockstep", True)
        rospy.set_param("/cart_sim/publish_rat", 5.0)
        result = subprocess.run(["roslaunch", PACKAGE, "driven.launch", "duration:=1"], stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, universal_newlines=True, timeout=60,
                                stdin=subprocess.DEVNULL)
        self.assertIn("final t = 1 s", result.stdout, result.stdout[-3000:])
        self.assertNotIn("publish_rat", result.stdout)
        self.assertFalse(rospy.has_param("/cart_sim/publish_rat"))

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
