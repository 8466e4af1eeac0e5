#!/usr/bin/python3
"""rostest cart_sim_reconfigure: cart_sim's limits and accuracy guard change while it runs, through
dynamic_reconfigure; a bad set is refused and the running settings stay."""
import threading
import time
import unittest

import rospy
import rostest
from birkhoff_cart.msg import IntegrationError
from dynamic_reconfigure.client import Client
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

PACKAGE = "birkhoff_cart"


class CartSimReconfigure(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("cart_sim_reconfigure", anonymous=True)
        cls.lock = threading.Lock()
        cls.joints = None
        cls.errors = []
        rospy.Subscriber("/joint_states", JointState, cls.on_joints, queue_size=10)
        rospy.Subscriber("/cart_sim/integration_error", IntegrationError, cls.on_error, queue_size=100)
        cls.steering = rospy.Publisher("/steering_torque", Float64, queue_size=10)
        cls.client = Client("/cart_sim", timeout=30)
        rospy.wait_for_message("/joint_states", JointState, timeout=30)

    @classmethod
    def on_joints(cls, message):
        with cls.lock:
            cls.joints = message

    @classmethod
    def on_error(cls, message):
        with cls.lock:
            cls.errors.append(message)

    def steering_effort_after(self, command, seconds=1.5):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            self.steering.publish(Float64(command))
            time.sleep(0.05)
        with self.lock:
            index = self.joints.name.index("steering_joint")
            return self.joints.effort[index]

    def test_1_a_new_steering_limit_clamps_the_next_commands(self):
        self.assertAlmostEqual(self.steering_effort_after(3.0), 3.0)  # within the start-up limit of 100 N m
        in_force = self.client.update_configuration({"max_steering_torque": 2.0})
        self.assertEqual(in_force["max_steering_torque"], 2.0)
        self.assertAlmostEqual(self.steering_effort_after(3.0), 2.0)
        self.assertAlmostEqual(self.steering_effort_after(-3.0), -2.0)
        self.client.update_configuration({"max_steering_torque": 100.0})
        self.assertAlmostEqual(self.steering_effort_after(0.0), 0.0)

    def test_2_a_bad_set_is_refused_and_the_running_settings_stay(self):
        before = self.client.get_configuration(timeout=10)
        in_force = self.client.update_configuration({"max_drive_torque": 0.0, "command_timeout": 2.0})
        self.assertEqual(in_force["max_drive_torque"], before["max_drive_torque"])
        self.assertEqual(in_force["command_timeout"], before["command_timeout"])  # the whole set refused
        in_force = self.client.update_configuration({"constraint_warn": 1.0, "constraint_error": 1e-3})
        self.assertEqual(in_force["constraint_warn"], before["constraint_warn"])

    def test_3_new_accuracy_limits_judge_the_next_instants(self):
        with self.lock:
            self.assertTrue(self.errors)
            self.assertEqual(self.errors[-1].accuracy_level, IntegrationError.ACCURACY_OK)
        # Any round-off trips a p2 balance limit of 1e-30 (off in the scene).
        in_force = self.client.update_configuration({"p2_balance_warn": 1e-30, "p2_balance_error": 1e-20})
        self.assertEqual(in_force["p2_balance_warn"], 1e-30)
        self.steering_effort_after(5.0, seconds=2.0)  # a torque moves p2, so its balance has round-off
        with self.lock:
            self.assertIn("p2_balance", self.errors[-1].accuracy_status)
            self.assertEqual(self.errors[-1].accuracy_level, IntegrationError.ACCURACY_ERROR)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "cart_sim_reconfigure", CartSimReconfigure)
