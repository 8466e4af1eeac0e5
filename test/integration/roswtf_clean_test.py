#!/usr/bin/python3
"""rostest roswtf_sim, roswtf_cmd_vel, roswtf_two_carts: roswtf's online checks (the graph and tf) are
clean on a running launch file of the package, with the user's tools beside it: rviz, whose 2D Pose
Estimate tool holds a publisher on each ~pose_topics (it publishes only on a click), and, for
~drive_topic (optional), a teleop driving that Twist topic at 10 Hz. Without them the simulator's
inputs are unconnected subscriptions, as any robot's are until something drives them."""
import subprocess
import threading
import unittest

import rospy
import rostest
from geometry_msgs.msg import PoseWithCovarianceStamped, Twist
from sensor_msgs.msg import JointState

PACKAGE = "birkhoff_cart"


class RoswtfClean(unittest.TestCase):
    def test_online_checks_are_clean(self):
        rospy.init_node("roswtf_clean", anonymous=True)
        joint_states = rospy.get_param("~joint_states", "/joint_states")
        rospy.wait_for_message(joint_states, JointState, timeout=60)
        # rviz's 2D Pose Estimate: advertised while rviz runs, published only on a click.
        pose_publishers = [rospy.Publisher(topic, PoseWithCovarianceStamped, queue_size=1)
                           for topic in rospy.get_param("~pose_topics", "/initialpose").split()]
        self.assertTrue(pose_publishers)
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
        self.assertIn("No errors or warnings", online, online)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "roswtf_clean", RoswtfClean)
