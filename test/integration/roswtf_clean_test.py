#!/usr/bin/python3
"""rostest roswtf_sim, roswtf_cmd_vel, roswtf_two_carts: roswtf's online checks (the graph and tf) are
clean on a running launch file of the package but for the user inputs no tool publishes yet
(~user_inputs: initialpose, which rviz's 2D Pose Estimate tool publishes; docs/ros_interface.md,
"Conventions"): its one warning may name those unconnected subscriptions and nothing else. With
~drive_topic (optional) a teleop drives that Twist topic at 10 Hz."""
import re
import subprocess
import threading
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from sensor_msgs.msg import JointState

PACKAGE = "birkhoff_cart"


class RoswtfClean(unittest.TestCase):
    def test_online_checks_are_clean(self):
        rospy.init_node("roswtf_clean", anonymous=True)
        joint_states = rospy.get_param("~joint_states", "/joint_states")
        rospy.wait_for_message(joint_states, JointState, timeout=60)
        user_inputs = set(rospy.get_param("~user_inputs", "/initialpose").split())
        drive_topic = rospy.get_param("~drive_topic", "")
        stop = threading.Event()
        if drive_topic:
            publisher = rospy.Publisher(drive_topic, Twist, queue_size=10)
            command = Twist()
            command.linear.x, command.angular.z = 1.0, 0.3

            def drive():
                while not stop.is_set():
                    publisher.publish(command)
                    stop.wait(0.1)

            threading.Thread(target=drive, daemon=True).start()
        rospy.sleep(1.0)  # the master knows the publishers
        try:
            # Outside any package directory: roswtf's static checks would otherwise look for ROS_ROOT.
            result = subprocess.run(["roswtf"], cwd="/tmp", stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                    universal_newlines=True, timeout=120, stdin=subprocess.DEVNULL)
        finally:
            stop.set()
        marker = "Online checks summary:"
        self.assertIn(marker, result.stdout, result.stdout)
        online = result.stdout[result.stdout.index(marker):]
        if "No errors or warnings" in online:
            return
        self.assertNotIn("ERROR", online, online)
        self.assertIn("Found 1 warning(s)", online, online)
        self.assertIn("The following node subscriptions are unconnected", online, online)
        # "   * /topic" lines (the " * /node:" lines above them end with a colon)
        unconnected = set(re.findall(r"^\s+\* (/[^\s:]+)$", online, re.MULTILINE))
        self.assertTrue(unconnected, online)
        self.assertLessEqual(unconnected, user_inputs, f"unconnected beyond the documented user inputs:\n{online}")


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "roswtf_clean", RoswtfClean)
