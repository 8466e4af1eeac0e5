#!/usr/bin/python3
"""rostest end_stop_pose: with the steering axle resting on its end stop (steering_actuator.yaml, stop
at 0.6 rad), joint_states never shows the steering angle past the stop and an /initialpose there is
taken (docs/ros_interface.md, "initialpose"; docs/actuators.md §3)."""
import math
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import JointState

from birkhoff_cart.srv import StepRun

STOP = 0.6          # the scene's steering_end_stops.angle [rad]
PLACED = 0.02       # how far the cart may move in the steps after a teleport [m]
STEPS_TO_REST = 600  # 6 s of the scene (h = 10 ms): the motor turns the axle from 2 s on and rests it on the stop by 4.5 s


class EndStopPose(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("end_stop_pose_test", anonymous=True)
        cls.lock = threading.Lock()
        cls.odometry = []
        cls.steering = []
        cls.log = []
        subscribers = [rospy.Subscriber("/odom", Odometry, cls.on_odometry, queue_size=1000),
                       rospy.Subscriber("/joint_states", JointState, cls.on_joints, queue_size=1000)]
        rospy.Subscriber("/rosout", Log, cls.on_log, queue_size=100)
        rospy.wait_for_service("/cart_sim/step", timeout=30.0)
        cls.step = rospy.ServiceProxy("/cart_sim/step", StepRun)
        cls.initial_pose = rospy.Publisher("/initialpose", PoseWithCovarianceStamped, queue_size=5)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and (cls.initial_pose.get_num_connections() == 0 or
                                               any(s.get_num_connections() == 0 for s in subscribers)):
            time.sleep(0.05)

    @classmethod
    def on_odometry(cls, message):
        with cls.lock:
            cls.odometry.append(message)

    @classmethod
    def on_joints(cls, message):
        with cls.lock:
            cls.steering.extend(p for n, p in zip(message.name, message.position) if n.endswith("steering_joint"))

    @classmethod
    def on_log(cls, message):
        if message.name.endswith("cart_sim"):
            with cls.lock:
                cls.log.append(message.msg)

    def odom_after(self, steps):
        with self.lock:
            count = len(self.odometry)
        answer = self.step(steps)
        self.assertTrue(answer.success, answer.message)
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline:
            with self.lock:
                if len(self.odometry) > count:
                    return self.odometry[-1]
            time.sleep(0.01)
        self.fail("no odom after the steps")

    def test_a_pose_with_the_axle_on_its_stop_is_taken(self):
        self.odom_after(STEPS_TO_REST)
        time.sleep(0.3)
        with self.lock:
            steering = list(self.steering)
        self.assertTrue(steering, "no joint_states")
        self.assertAlmostEqual(abs(steering[-1]), STOP, delta=1e-9, msg="the axle is not resting on its stop")
        self.assertLessEqual(max(abs(chi) for chi in steering), STOP, "the axle passed its stop")
        message = PoseWithCovarianceStamped()
        message.header.frame_id = "odom"
        message.pose.pose.position.x, message.pose.pose.position.y = -3.0, 1.0
        message.pose.pose.orientation.z, message.pose.pose.orientation.w = math.sin(0.5), math.cos(0.5)
        self.initial_pose.publish(message)
        time.sleep(0.5)  # the paused node runs the callback while it waits
        placed = self.odom_after(5).pose.pose
        with self.lock:
            refusals = [line for line in self.log if "refused" in line]
        self.assertEqual(refusals, [])
        self.assertAlmostEqual(placed.position.x, -3.0, delta=PLACED)
        self.assertAlmostEqual(placed.position.y, 1.0, delta=PLACED)


if __name__ == "__main__":
    rostest.rosrun("birkhoff_cart", "end_stop_pose", EndStopPose)
