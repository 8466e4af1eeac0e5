#!/usr/bin/python3
"""rostest teleport_checks: ~set_state and initialpose are checked before they are committed
(docs/ros_interface.md, "~set_state", "initialpose"). Before the fix `~set_state 1 1 0 0
1e200 0` answered success and the next step killed the node; x = 1e20, heading and chi 1e300 and
1e6 m/s were accepted; an initialpose with an empty frame was taken as odom, and its NaN refusal did
not name the field."""
import math
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log

from birkhoff_cart.srv import SetCartState, StepRun

PLACED = 0.02     # how far the cart may move in the 5 steps after a teleport [m]
WENT_ON = 0.1     # how far it may move in the 20 steps of a run that went on [m]


class TeleportChecks(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("teleport_checks_test", anonymous=True)
        cls.lock = threading.Lock()
        cls.odometry = []
        cls.log = []
        odometry = rospy.Subscriber("/odom", Odometry, cls.on_odometry, queue_size=100)
        rospy.Subscriber("/rosout", Log, cls.on_log, queue_size=100)
        rospy.wait_for_service("/cart_sim/set_state", timeout=30.0)
        cls.set_state = rospy.ServiceProxy("/cart_sim/set_state", SetCartState)
        cls.step = rospy.ServiceProxy("/cart_sim/step", StepRun)
        cls.initial_pose = rospy.Publisher("/initialpose", PoseWithCovarianceStamped, queue_size=5)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and (cls.initial_pose.get_num_connections() == 0 or
                                               odometry.get_num_connections() == 0):
            time.sleep(0.05)

    @classmethod
    def on_odometry(cls, message):
        with cls.lock:
            cls.odometry.append(message)

    @classmethod
    def on_log(cls, message):
        if message.name.endswith("cart_sim"):
            with cls.lock:
                cls.log.append(message)

    def position_after(self, steps):
        """Steps the paused run (h = 10 ms; 5 steps = one publish instant) and returns the last odom position."""
        with self.lock:
            count = len(self.odometry)
        answer = self.step(steps)
        self.assertTrue(answer.success, answer.message)
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline:
            with self.lock:
                if len(self.odometry) > count:
                    pose = self.odometry[-1].pose.pose
                    return pose.position.x, pose.position.y
            time.sleep(0.01)
        self.fail("no odom after the steps")

    def log_line_with(self, text, seconds=5.0):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            with self.lock:
                for line in self.log:
                    if text in line.msg:
                        return line
            time.sleep(0.05)
        with self.lock:
            self.fail(f"no log line of cart_sim with '{text}'; got: {[line.msg for line in self.log][-5:]}")

    def test_1_set_state_values_no_step_resolves_are_refused_by_name(self):
        self.assertTrue(self.set_state(2.0, 1.0, 0.0, 0.0, 0.0, 0.0).success)
        start = self.position_after(5)
        # x y heading steering_angle forward_speed steering_rate, and the field to be named
        cases = [((1.0, 1.0, 0.0, 0.0, 1.0e200, 0.0), "forward_speed"),
                 ((1.0, 1.0, 0.0, 0.0, 1.0e6, 0.0), "forward_speed"),
                 ((1.0e20, 1.0, 0.0, 0.0, 0.0, 0.0), "x"),
                 ((1.0, 1.0, 1.0e300, 0.0, 0.0, 0.0), "heading"),
                 ((1.0, 1.0, 0.0, 1.0e300, 0.0, 0.0), "steering_angle"),
                 ((1.0, 1.0, 0.0, 0.0, 0.0, 1.0e6), "steering_rate")]
        for request, field in cases:
            answer = self.set_state(*request)
            self.assertFalse(answer.success, f"{request} was accepted: {answer.message}")
            self.assertIn(f"~set_state refused: restart state: {field} ", answer.message)
            self.assertIn("the simulation goes on unchanged", answer.message)
        # The run went on from (2, 1), alive: the steps after the refusals are the run's own.
        after = self.position_after(20)
        self.assertAlmostEqual(after[0], start[0], delta=WENT_ON)
        self.assertAlmostEqual(after[1], start[1], delta=WENT_ON)

    def send_initial_pose(self, frame, x, y, yaw=0.0):
        message = PoseWithCovarianceStamped()
        message.header.frame_id = frame
        message.pose.pose.position.x, message.pose.pose.position.y = x, y
        message.pose.pose.orientation.z, message.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        self.initial_pose.publish(message)
        time.sleep(0.3)  # the paused node runs the callback while it waits

    def test_2_initial_pose_with_an_empty_frame_or_nan_is_refused_by_name(self):
        self.assertTrue(self.set_state(-4.0, 3.0, 0.0, 0.0, 0.0, 0.0).success)
        self.send_initial_pose("", 9.0, 9.0)
        self.log_line_with("header.frame_id is empty")
        self.send_initial_pose("odom", float("nan"), 9.0)
        self.log_line_with("pose.pose.position.x must be finite, got nan")
        x, y = self.position_after(20)
        self.assertAlmostEqual(x, -4.0, delta=WENT_ON)
        self.assertAlmostEqual(y, 3.0, delta=WENT_ON)

    def test_3_initial_pose_in_a_frame_fixed_to_odom_on_tf_static(self):
        # world -> map is (0, 6) (static_transform_publisher), map -> odom cart_sim's identity.
        self.send_initial_pose("world", 1.0, 7.0, 0.5)
        x, y = self.position_after(5)
        self.assertAlmostEqual(x, 1.0, delta=PLACED)
        self.assertAlmostEqual(y, 1.0, delta=PLACED)
        self.send_initial_pose("nowhere", 5.0, 5.0)  # no static transform to odom: refused by name
        self.log_line_with("the pose is in frame 'nowhere', which /tf_static does not fix to 'odom'")


if __name__ == "__main__":
    rostest.rosrun("birkhoff_cart", "teleport_checks", TeleportChecks)
