#!/usr/bin/python3
"""rostest cmd_vel_conformance: cmd_vel_controller against the cases ros_controllers checks for its
Twist-driven controllers, on the simulated cart (config/cmd_vel_controller.yaml: v in [-1, 3] m/s,
|a| <= 1.5 m/s² up, 3 m/s² down, cmd_vel_timeout 0.5 s). Speeds and yaw rates are read from odom
(base_link, the rear-axle midpoint)."""
import subprocess
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

PACKAGE = "birkhoff_cart"


class CmdVelConformance(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("cmd_vel_conformance", anonymous=True)
        cls.publisher = rospy.Publisher("/cmd_vel", Twist, queue_size=10)
        cls.lock = threading.Lock()
        cls.odometry = None
        rospy.Subscriber("/odom", Odometry, cls.on_odometry, queue_size=10)
        deadline = time.monotonic() + 30.0
        while cls.odometry is None and time.monotonic() < deadline:
            time.sleep(0.1)

    @classmethod
    def on_odometry(cls, message):
        with cls.lock:
            cls.odometry = message

    def drive(self, speed, yaw_rate, seconds):
        """Publishes the Twist at 20 Hz of wall time for `seconds`; returns the odom twists seen."""
        command = Twist()
        command.linear.x, command.angular.z = speed, yaw_rate
        seen = []
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.publisher.publish(command)
            time.sleep(0.05)
            with self.lock:
                seen.append((self.odometry.twist.twist.linear.x, self.odometry.twist.twist.angular.z))
        return seen

    def settle(self):
        """Silence until the cart is at rest (the timeout brakes it)."""
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline:
            time.sleep(0.2)
            with self.lock:
                if abs(self.odometry.twist.twist.linear.x) < 1e-3:
                    return
        self.fail("the cart did not come to rest after cmd_vel fell silent")

    def test_1_tracks_a_forward_speed(self):
        self.assertIsNotNone(self.odometry, "no odom from cart_sim")
        seen = self.drive(1.0, 0.0, 4.0)
        speed, yaw_rate = seen[-1]
        self.assertAlmostEqual(speed, 1.0, delta=0.05)
        self.assertAlmostEqual(yaw_rate, 0.0, delta=0.02)

    def test_2_tracks_a_yaw_rate(self):
        seen = self.drive(1.0, 0.3, 5.0)
        speed, yaw_rate = seen[-1]
        self.assertAlmostEqual(speed, 1.0, delta=0.05)
        self.assertAlmostEqual(yaw_rate, 0.3, delta=0.03)

    def test_3_clamps_a_speed_beyond_the_limit(self):
        seen = self.drive(10.0, 0.0, 4.0)
        speeds = [speed for speed, _ in seen]
        self.assertLessEqual(max(speeds), 3.0 + 0.05)
        self.assertGreater(speeds[-1], 2.8)

    def test_4_brakes_to_rest_when_cmd_vel_falls_silent(self):
        self.drive(1.0, 0.0, 2.0)
        self.settle()

    def test_5_refuses_a_steering_joint_missing_from_joint_states(self):
        started = time.monotonic()
        result = subprocess.run(["rosrun", PACKAGE, "cmd_vel_controller", "__name:=wrong_joint_controller",
                                 "__ns:=/wrong_joint", "joint_states:=/joint_states", "odom:=/odom",
                                 "_steering_joint:=stering_joint"],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                timeout=30, stdin=subprocess.DEVNULL)
        seconds = time.monotonic() - started
        self.assertEqual(result.returncode, 2, result.stdout)
        self.assertIn("joint 'stering_joint' (/wrong_joint/wrong_joint_controller/steering_joint) is not in "
                      "/joint_states", result.stdout)
        self.assertIn("(did you mean 'steering_joint'?)", result.stdout)
        self.assertLess(seconds, 10.0, "refused after %.1f s (about a second after the first joint_states)" % seconds)

    def test_6_names_a_misspelled_parameter(self):
        process = subprocess.Popen(["rosrun", PACKAGE, "cmd_vel_controller", "__name:=typo_controller",
                                    "__ns:=/typo", "joint_states:=/joint_states", "odom:=/odom",
                                    "_cmd_vel_timout:=0.5"],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                   stdin=subprocess.DEVNULL)
        output = []
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline:
            line = process.stdout.readline()
            if not line:
                break
            output.append(line)
            if "cmd_vel_timout" in line:
                break
        process.terminate()
        process.wait(timeout=10)
        self.assertIn("parameter /typo/typo_controller/cmd_vel_timout is not one of this node's and is ignored "
                      "(did you mean /typo/typo_controller/cmd_vel_timeout?)", "".join(output))

    def test_7_takes_new_limits_while_running_and_refuses_a_bad_set(self):
        from dynamic_reconfigure.client import Client
        client = Client("/cmd_vel_controller", timeout=20)
        in_force = client.update_configuration({"linear_x_max_velocity": 2.0})
        self.assertEqual(in_force["linear_x_max_velocity"], 2.0)
        speeds = [speed for speed, _ in self.drive(10.0, 0.0, 4.0)]
        self.assertLessEqual(max(speeds), 2.0 + 0.05)
        self.assertGreater(speeds[-1], 1.8)
        # Braking must stay a deceleration: 0 is refused, the running settings stay.
        in_force = client.update_configuration({"linear_x_min_acceleration": 0.0})
        self.assertEqual(in_force["linear_x_min_acceleration"], -3.0)
        self.assertEqual(in_force["linear_x_max_velocity"], 2.0)
        client.update_configuration({"linear_x_max_velocity": 3.0})
        self.settle()


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "cmd_vel_conformance", CmdVelConformance)
