#!/usr/bin/python3
"""rostest actuators: cart_sim on a scene with a steering motor (T = 0.2 s, d = 0.05 s, 5 N·m/s rate
limit, 2 N·m saturation), a drive motor (T = 0.3 s, 4 N·m saturation) and end stops at ±0.5 rad
(test/integration/actuators_scene.yaml, docs/actuators.md). Paused at t = 0, commanded 3 N·m steering
and 10 N·m drive, then advanced 3000 steps (3 s) with ~step."""
import math
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from birkhoff_cart.srv import StepRun

STEPS = 3000  # of h = 1 ms: 3 s
STOP = 0.5  # [rad]


def steering_applied(t):
    """(A1), (A5), (A4): 3 N·m saturated to 2, 50 ms dead time, then a 5 N·m/s ramp while the 0.2 s lag
    would be faster (until |2 − τ| = R T = 1 N·m at t = 0.25 s), then the lag, from rest at 0 [N·m]."""
    if t <= 0.05:
        return 0.0
    if t <= 0.25:
        return 5.0 * (t - 0.05)
    return 2.0 - 1.0 * math.exp(-(t - 0.25) / 0.2)


def drive_applied(t):
    """10 N·m saturated to 4, 0.3 s lag [N·m]; each rear wheel's effort is half of it."""
    return 4.0 * (1.0 - math.exp(-t / 0.3))


class Actuators(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("actuators_test", anonymous=True)
        cls.lock = threading.Lock()
        cls.joints = []
        cls.diagnostics = []
        rospy.Subscriber("/joint_states", JointState, cls.on_joints, queue_size=1000)
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=100)
        steering = rospy.Publisher("/steering_torque", Float64, queue_size=1, latch=True)
        drive = rospy.Publisher("/drive_torque", Float64, queue_size=1, latch=True)
        rospy.wait_for_service("/cart_sim/step", timeout=30.0)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and (steering.get_num_connections() == 0 or drive.get_num_connections() == 0):
            time.sleep(0.05)
        steering.publish(Float64(3.0))
        drive.publish(Float64(10.0))
        time.sleep(1.0)  # both commands held by the paused node before its first step
        cls.answer = rospy.ServiceProxy("/cart_sim/step", StepRun)(STEPS)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            with cls.lock:
                if any(abs(m.header.stamp.to_sec() - 3.0) < 1e-9 for m in cls.joints):
                    break
            time.sleep(0.05)
        time.sleep(2.5)  # a /diagnostics message after the steps
        with cls.lock:
            cls.series = {round(m.header.stamp.to_sec(), 9): m for m in cls.joints}

    @classmethod
    def on_joints(cls, message):
        with cls.lock:
            cls.joints.append(message)

    @classmethod
    def on_diagnostics(cls, message):
        with cls.lock:
            cls.diagnostics.append(message)

    def instants(self):
        self.assertTrue(self.answer.success, self.answer.message)
        instants = [round(0.05 * k, 9) for k in range(1, 61)]
        for instant in instants:
            self.assertIn(instant, self.series, f"no joint_states at t = {instant} s")
        return instants

    def test_1_steering_effort_is_the_actuators_response(self):
        for t in self.instants():
            joints = self.series[t]
            steering = joints.name.index("steering_joint")
            self.assertAlmostEqual(joints.effort[steering], steering_applied(t), delta=1e-12, msg=f"t = {t} s")

    def test_2_drive_efforts_are_the_actuators_response(self):
        for t in self.instants():
            joints = self.series[t]
            for wheel in ("rear_left_wheel_joint", "rear_right_wheel_joint"):
                self.assertAlmostEqual(joints.effort[joints.name.index(wheel)], 0.5 * drive_applied(t), delta=1e-12,
                                       msg=f"{wheel} at t = {t} s")

    def test_3_the_axle_stops_at_its_end_stop_and_rests_there(self):
        angles = []
        for t in self.instants():
            joints = self.series[t]
            angles.append(joints.position[joints.name.index("steering_joint")])
        self.assertLessEqual(max(angles), STOP + 1e-12, "the steering angle passed its end stop")
        final = self.series[3.0]
        steering = final.name.index("steering_joint")
        self.assertAlmostEqual(final.position[steering], STOP, delta=1e-12)
        self.assertAlmostEqual(final.velocity[steering], 0.0, delta=1e-12)
        first = next(k for k, angle in enumerate(angles) if abs(angle - STOP) < 1e-12)
        self.assertTrue(all(abs(angle - STOP) < 1e-12 for angle in angles[first:]), "the axle left the stop")

    def test_4_diagnostics_show_the_actuators(self):
        with self.lock:
            statuses = [status for message in self.diagnostics for status in message.status
                        if status.name.endswith(": simulation")]
        self.assertTrue(statuses, "no cart_sim simulation status on /diagnostics")
        values = {pair.key: pair.value for pair in statuses[-1].values}
        self.assertEqual(values.get("steering end stop contact"), "upper", values)
        self.assertEqual(values.get("steering end stop events"), "1")
        # The values are printed with 6 significant digits.
        self.assertAlmostEqual(float(values["steering actuator input [N m]"]), 3.0)
        self.assertAlmostEqual(float(values["steering actuator applied [N m]"]), steering_applied(3.0), delta=1e-5)
        self.assertAlmostEqual(float(values["drive actuator applied [N m]"]), drive_applied(3.0), delta=1e-5)


if __name__ == "__main__":
    rostest.rosrun("birkhoff_cart", "actuators", Actuators)
