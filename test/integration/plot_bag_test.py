#!/usr/bin/python3
"""rostest plot_bag: `rosrun birkhoff_cart plot_bag` on a fresh cart_sim bag writes a PNG of the
expected size with no "File system loop detected" from rosrun; a missing bag and a bag without
cart_sim's topics are refused with exit 2 and a message naming the problem."""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest

import rosbag
import rospkg
import rostest
from std_msgs.msg import String
import rospy

PACKAGE = "birkhoff_cart"
RUN_LIMIT = 90  # [s of wall time], only against hangs


def run(command):
    return subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                          timeout=RUN_LIMIT, stdin=subprocess.DEVNULL)


def plot_bag(*arguments):
    """plot_bag itself, without rosrun's search of the package (the user's path, through rosrun, is
    test_plots_a_cart_sim_bag's first call)."""
    script = os.path.join(rospkg.RosPack().get_path(PACKAGE), "scripts", "plot_bag")
    return run([script] + list(arguments))


def png_size(path):
    """(width, height) from the PNG's IHDR chunk; raises when the file is not a PNG."""
    with open(path, "rb") as png:
        header = png.read(24)
    if header[:8] != b"\x89PNG\r\n\x1a\n" or header[12:16] != b"IHDR":
        raise AssertionError("%s is not a PNG" % path)
    return struct.unpack(">II", header[16:24])


class PlotBag(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.directory = tempfile.mkdtemp(prefix="plot_bag_test_")
        cls.bag = os.path.join(cls.directory, "run.bag")
        scene = os.path.join(rospkg.RosPack().get_path(PACKAGE), "config", "scenes", "default.yaml")
        # 2 s of the default scene (it has a shadow reference, so every panel has data), fast.
        cls.simulator = run(["rosrun", PACKAGE, "cart_sim", "__name:=plot_bag_cart_sim", "_scene:=" + scene,
                             "_fast:=true", "_duration:=2.0", "_publish_rate:=50", "_bag_path:=" + cls.bag])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.directory, ignore_errors=True)

    def test_plots_a_cart_sim_bag(self):
        self.assertEqual(self.simulator.returncode, 0, self.simulator.stderr)
        self.assertTrue(os.path.isfile(self.bag))
        result = run(["rosrun", PACKAGE, "plot_bag", self.bag])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertNotIn("File system loop", result.stderr)
        png = os.path.join(self.directory, "run.png")  # default: the bag's path with .png
        self.assertIn("wrote " + png, result.stdout)
        # 100 instants per stream at 50 Hz over 2 s.
        self.assertIn("/odom: 100", result.stdout)
        self.assertIn("/plot_bag_cart_sim/integration_error: 100", result.stdout)
        self.assertEqual(png_size(png), (1200, 680))  # 15 x 8.5 in at 80 dpi

        other = os.path.join(self.directory, "elsewhere.png")
        result = plot_bag(self.bag, "-o", other)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(png_size(other), (1200, 680))

    def test_refuses_a_missing_bag(self):
        missing = os.path.join(self.directory, "missing.bag")
        result = plot_bag(missing)
        self.assertEqual(result.returncode, 2)
        self.assertIn("no bag at " + missing, result.stderr)

    def test_refuses_a_bag_without_cart_topics(self):
        foreign = os.path.join(self.directory, "foreign.bag")
        with rosbag.Bag(foreign, "w") as bag:
            bag.write("/chatter", String(data="hello"), rospy.Time(1.0))
        result = plot_bag(foreign)
        self.assertEqual(result.returncode, 2)
        self.assertIn("is it a cart_sim bag?", result.stderr)
        self.assertIn("/chatter", result.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.directory, "foreign.png")))


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "plot_bag", PlotBag, sys.argv)
