#!/usr/bin/python3
"""rostest cart_sim_reconfigure: cart_sim's limits and accuracy guard change while it runs, through
dynamic_reconfigure; a bad set is refused and the running settings stay. A refusal is seen: the set
answers with the settings in force and a WARN line names the value typed (before, the cfg's
limits clamped -5 to 0 before the node saw it, and cmd_vel_controller's steering_max_angle 2.0
silently became 1.57)."""
import threading
import time
import unittest

import rospy
import rostest
from birkhoff_cart.msg import IntegrationError
from rosgraph_msgs.msg import Log
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
        cls.log = []
        rospy.Subscriber("/rosout", Log, cls.on_log, queue_size=100)
        rospy.Subscriber("/joint_states", JointState, cls.on_joints, queue_size=10)
        rospy.Subscriber("/cart_sim/integration_error", IntegrationError, cls.on_error, queue_size=100)
        cls.steering = rospy.Publisher("/steering_torque", Float64, queue_size=10)
        cls.client = Client("/cart_sim", timeout=30)
        rospy.wait_for_message("/joint_states", JointState, timeout=30)

    @classmethod
    def on_log(cls, message):
        with cls.lock:
            cls.log.append(message)

    def warning_with(self, node, text, seconds=5.0):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            with self.lock:
                if any(line.name == node and line.level == Log.WARN and text in line.msg for line in self.log):
                    return
            time.sleep(0.05)
        with self.lock:
            self.fail(f"no WARN of {node} with '{text}': {[line.msg for line in self.log if line.name == node][-5:]}")

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

    def test_2b_a_refusal_names_the_value_typed_and_answers_the_settings_in_force(self):
        before = self.client.get_configuration(timeout=10)
        for name, typed in (("max_steering_torque", -5.0), ("command_timeout", -1.0), ("max_drive_torque", -7.5)):
            in_force = self.client.update_configuration({name: typed})
            self.assertEqual(in_force[name], before[name], f"{name} {typed} was not refused")
            self.warning_with("/cart_sim", f"{name} must be finite and ")
            self.warning_with("/cart_sim", f"got {typed:g}")
        self.assertEqual(self.client.get_configuration(timeout=10)["max_steering_torque"], before["max_steering_torque"])
        # A value beyond what a clamping cfg allowed, and valid for the node: taken as typed.
        in_force = self.client.update_configuration({"max_drive_torque": 2e9})
        self.assertEqual(in_force["max_drive_torque"], 2e9)
        self.client.update_configuration({"max_drive_torque": before["max_drive_torque"]})

    def test_2c_cmd_vel_controller_refusals_name_the_value_typed(self):
        controller = Client("/cmd_vel_controller", timeout=30)
        before = controller.get_configuration(timeout=10)
        in_force = controller.update_configuration({"steering_max_angle": 2.0})  # >= pi/2
        self.assertEqual(in_force["steering_max_angle"], before["steering_max_angle"])
        self.warning_with("/cmd_vel_controller", "steering/max_angle must be > 0 and < pi/2 rad, got 2")
        in_force = controller.update_configuration({"steering_p": -5.0})
        self.assertEqual(in_force["steering_p"], before["steering_p"])
        self.warning_with("/cmd_vel_controller", "steering/p must be finite and > 0 N m/rad, got -5")

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
