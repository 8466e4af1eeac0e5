#!/usr/bin/python3
"""rostest pose_and_step: cart_sim's ~step, ~set_state and /initialpose (docs/ros_interface.md,
"Pose and time control"), on two carts of the default scene (h = 10 ms, published at 20 Hz)."""
import math
import os
import threading
import time
import unittest

import rosbag
import rospy
import rostest
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry
from std_srvs.srv import SetBool

from birkhoff_cart.srv import SetCartState, StepRun

STEP = 0.01           # the default scene's h [s]
PUBLISH_PERIOD = 0.05  # 1 / ~publish_rate [s]
TELEPORT_TOLERANCE = 0.02  # how far the cart may move in one publish period after a teleport [m], [rad]


def yaw_of(pose):
    q = pose.orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def key_of(message):
    """Everything odom says about the state, for bit-for-bit comparison."""
    p, t = message.pose.pose, message.twist.twist
    return (p.position.x, p.position.y, p.orientation.z, p.orientation.w, t.linear.x, t.linear.y, t.angular.z)


class PoseAndStep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("pose_and_step", anonymous=True)
        cls.lock = threading.Lock()
        cls.odometry = {"free": [], "stepped": []}
        subscribers = [rospy.Subscriber(f"/{cart}/odom", Odometry, cls.on_odometry, callback_args=cart, queue_size=1000)
                       for cart in cls.odometry]
        for service in ("/free/cart_sim/pause", "/stepped/cart_sim/step", "/stepped/cart_sim/set_state"):
            rospy.wait_for_service(service, timeout=30.0)
        cls.step = rospy.ServiceProxy("/stepped/cart_sim/step", StepRun)
        cls.set_state = rospy.ServiceProxy("/stepped/cart_sim/set_state", SetCartState)
        cls.pause = rospy.ServiceProxy("/stepped/cart_sim/pause", SetBool)
        cls.initial_pose = rospy.Publisher("/stepped/initialpose", PoseWithCovarianceStamped, queue_size=5)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and (cls.initial_pose.get_num_connections() == 0 or
                                               any(s.get_num_connections() == 0 for s in subscribers)):
            time.sleep(0.05)

    @classmethod
    def on_odometry(cls, message, cart):
        with cls.lock:
            cls.odometry[cart].append(message)

    def latest(self, cart, after_count, seconds=10.0):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            with self.lock:
                if len(self.odometry[cart]) > after_count:
                    return self.odometry[cart][-1]
            time.sleep(0.01)
        self.fail(f"no new odom from {cart} within {seconds} s")

    def stepped_odom_after(self, steps):
        with self.lock:
            count = len(self.odometry["stepped"])
        answer = self.step(steps)
        self.assertTrue(answer.success, answer.message)
        return self.latest("stepped", count), answer

    def test_1_steps_while_paused_equal_the_unpaused_run_bit_for_bit(self):
        rospy.ServiceProxy("/free/cart_sim/pause", SetBool)(False)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            with self.lock:
                if any(abs(m.header.stamp.to_sec() - 2.0) < 1e-9 for m in self.odometry["free"]):
                    break
            time.sleep(0.05)
        taken = 0
        for steps in (7, 13, 1, 79, 100):  # ends off and on publish instants; 200 steps = 2 s
            answer = self.step(steps)
            taken += steps
            self.assertTrue(answer.success, answer.message)
            self.assertEqual(answer.steps_taken, steps)
            self.assertAlmostEqual(answer.time, taken * STEP, delta=1e-12)
        time.sleep(0.5)
        with self.lock:
            free = {round(m.header.stamp.to_sec(), 9): key_of(m) for m in self.odometry["free"]}
            stepped = {round(m.header.stamp.to_sec(), 9): key_of(m) for m in self.odometry["stepped"]}
        instants = [round(k * PUBLISH_PERIOD, 9) for k in range(1, 41)]
        for instant in instants:
            self.assertIn(instant, free, f"the free run published no odom at t = {instant} s")
            self.assertIn(instant, stepped, f"the stepped run published no odom at t = {instant} s")
            self.assertEqual(stepped[instant], free[instant], f"odom differs at t = {instant} s")
        between = [t for t in stepped if abs(t / PUBLISH_PERIOD - round(t / PUBLISH_PERIOD)) > 1e-6]
        self.assertEqual(between, [], "the stepped run published between its publish instants")

    def test_2_step_refusals_name_the_problem(self):
        answer = self.step(0)
        self.assertFalse(answer.success)
        self.assertIn("at least 1", answer.message)
        self.pause(False)
        try:
            answer = self.step(5)
            self.assertFalse(answer.success)
            self.assertIn("not paused", answer.message)
        finally:
            self.pause(True)
        time.sleep(0.2)

    def test_3_set_state_teleports_and_refuses_a_bad_state(self):
        answer = self.set_state(x=5.0, y=2.0, heading=0.5, steering_angle=0.1, forward_speed=0.0, steering_rate=0.0)
        self.assertTrue(answer.success, answer.message)
        odom, step = self.stepped_odom_after(5)
        pose = odom.pose.pose
        self.assertAlmostEqual(pose.position.x, 5.0, delta=TELEPORT_TOLERANCE)
        self.assertAlmostEqual(pose.position.y, 2.0, delta=TELEPORT_TOLERANCE)
        self.assertAlmostEqual(yaw_of(pose), 0.5, delta=TELEPORT_TOLERANCE)
        self.assertLess(abs(odom.twist.twist.linear.x), 0.2)  # from rest, 0.05 s of the scene's drive torque
        for field in ("x", "heading", "steering_rate"):
            request = dict(x=1.0, y=1.0, heading=0.0, steering_angle=0.0, forward_speed=0.0, steering_rate=0.0)
            request[field] = float("nan")
            answer = self.set_state(**request)
            self.assertFalse(answer.success)
            self.assertIn(f"{field} must be finite", answer.message)
        after, _ = self.stepped_odom_after(5)  # the run went on from the teleport, not from (1, 1)
        self.assertAlmostEqual(after.pose.pose.position.x, 5.0, delta=2 * TELEPORT_TOLERANCE)
        self.assertGreater(after.header.stamp.to_sec(), odom.header.stamp.to_sec())  # time went on

    def send_initial_pose(self, frame, x, y, yaw):
        message = PoseWithCovarianceStamped()
        message.header.frame_id = frame
        message.pose.pose.position.x, message.pose.pose.position.y = x, y
        message.pose.pose.orientation.z, message.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        self.initial_pose.publish(message)
        time.sleep(0.3)  # the paused node runs the callback while it waits

    def test_4_initial_pose_from_rviz_teleports_in_the_odom_or_map_frame_only(self):
        self.send_initial_pose("odom", -3.0, 1.0, 1.0)
        odom, _ = self.stepped_odom_after(5)
        pose = odom.pose.pose
        self.assertAlmostEqual(pose.position.x, -3.0, delta=TELEPORT_TOLERANCE)
        self.assertAlmostEqual(pose.position.y, 1.0, delta=TELEPORT_TOLERANCE)
        self.assertAlmostEqual(yaw_of(pose), 1.0, delta=TELEPORT_TOLERANCE)
        self.send_initial_pose("base_link", 40.0, 40.0, 0.0)  # not a frame cart_sim places the cart in: refused
        after, _ = self.stepped_odom_after(5)
        self.assertAlmostEqual(after.pose.pose.position.x, -3.0, delta=2 * TELEPORT_TOLERANCE)
        # map, rviz's default fixed frame: the same coordinates while map -> odom is cart_sim's identity.
        self.send_initial_pose("map", 7.0, -2.0, -0.5)
        placed, _ = self.stepped_odom_after(5)
        self.assertAlmostEqual(placed.pose.pose.position.x, 7.0, delta=TELEPORT_TOLERANCE)
        self.assertAlmostEqual(placed.pose.pose.position.y, -2.0, delta=TELEPORT_TOLERANCE)
        self.assertAlmostEqual(yaw_of(placed.pose.pose), -0.5, delta=TELEPORT_TOLERANCE)

    def test_5_the_bag_goes_on_across_teleports_and_step_runs_out_at_the_end(self):
        bag_path = rospy.get_param("/stepped/cart_sim/bag_path")
        answer = self.step(5000)  # more than the 30 s run has left
        self.assertFalse(answer.success)
        self.assertIn("ran out", answer.message)
        self.assertLess(answer.steps_taken, 5000)
        self.assertAlmostEqual(answer.time, 30.0, delta=1e-9)
        deadline = time.monotonic() + 30.0
        while not os.path.exists(bag_path) and time.monotonic() < deadline:
            time.sleep(0.1)
        self.assertTrue(os.path.exists(bag_path), f"cart_sim left no bag at {bag_path}")
        stem = bag_path[:-len(".bag")]
        self.assertFalse(os.path.exists(stem + "_run2.bag"), "a teleport started a new run file")
        with rosbag.Bag(bag_path) as bag:
            odometry = [(m.header.stamp.to_sec(), m.pose.pose.position.x)
                        for _, m, _ in bag.read_messages(topics=["/stepped/odom"])]
        stamps = [stamp for stamp, _ in odometry]
        self.assertGreater(len(stamps), 100)
        self.assertTrue(all(b > a for a, b in zip(stamps, stamps[1:])), "odom stamps in the bag went back")
        self.assertAlmostEqual(stamps[-1], 30.0, delta=1e-9)
        self.assertTrue(any(abs(x - 5.0) < TELEPORT_TOLERANCE for _, x in odometry))   # ~set_state's pose
        self.assertTrue(any(abs(x + 3.0) < TELEPORT_TOLERANCE for _, x in odometry))   # /initialpose's pose
        os.remove(bag_path)


if __name__ == "__main__":
    rostest.rosrun("birkhoff_cart", "pose_and_step", PoseAndStep)
