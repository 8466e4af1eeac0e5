#!/usr/bin/python3
"""rostest example_controllers: steering_pd_controller and steering_driver beside a running cart_sim
(its joint_states on /joint_states) refuse or name their configuration mistakes."""
import subprocess
import time
import unittest

import rospy
import rostest
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

PACKAGE = "birkhoff_cart"


def output_until(command, marker, seconds):
    """Runs `command` until a line holds `marker` or `seconds` pass; returns its output so far."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                               stdin=subprocess.DEVNULL)
    output = []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        line = process.stdout.readline()
        if not line:
            break
        output.append(line)
        if marker in line:
            break
    process.terminate()
    process.wait(timeout=10)
    return "".join(output)


class ExampleControllers(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("example_controllers", anonymous=True)
        rospy.wait_for_message("/joint_states", JointState, timeout=30)

    def test_1_steering_pd_controller_refuses_a_steering_joint_missing_from_joint_states(self):
        started = time.monotonic()
        result = subprocess.run(["rosrun", PACKAGE, "steering_pd_controller", "__ns:=/wrong_joint",
                                 "joint_states:=/joint_states", "_steering_joint:=stering_joint"],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                timeout=30, stdin=subprocess.DEVNULL)
        seconds = time.monotonic() - started
        self.assertEqual(result.returncode, 2, result.stdout)
        self.assertIn("joint 'stering_joint' (~steering_joint) is not in /joint_states, which names steering_joint, ",
                      result.stdout)
        self.assertIn("(did you mean 'steering_joint'?)", result.stdout)
        self.assertLess(seconds, 10.0, "refused after %.1f s (about a second after the first joint_states)" % seconds)

    def test_2_steering_pd_controller_runs_with_a_joint_that_joint_states_holds(self):
        process = subprocess.Popen(["rosrun", PACKAGE, "steering_pd_controller", "__ns:=/right_joint",
                                    "joint_states:=/joint_states", "_steering_joint:=steering_joint"],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                   stdin=subprocess.DEVNULL)
        try:
            torque = rospy.wait_for_message("/right_joint/steering_torque", Float64, timeout=20)
            self.assertTrue(abs(torque.data) < 1e3)
            time.sleep(2.5)  # past the 1 s a wrong name would be given
            self.assertIsNone(process.poll(), "the controller exited with a joint that joint_states holds")
            rospy.wait_for_message("/right_joint/steering_torque", Float64, timeout=5)
        finally:
            process.terminate()
            process.wait(timeout=10)

    def test_3_a_misspelled_parameter_is_named_with_the_closest_known_one(self):
        output = output_until(["rosrun", PACKAGE, "steering_pd_controller", "__name:=typo_pd", "__ns:=/typo",
                               "joint_states:=/joint_states", "_kpp:=3.0"], "kpp", 20)
        self.assertIn("parameter /typo/typo_pd/kpp is not one of this node's and is ignored "
                      "(did you mean /typo/typo_pd/kp?)", output)
        output = output_until(["rosrun", PACKAGE, "steering_driver", "__name:=typo_driver", "__ns:=/typo",
                               "_amplitud:=1.0"], "amplitud", 20)
        self.assertIn("parameter /typo/typo_driver/amplitud is not one of this node's and is ignored "
                      "(did you mean /typo/typo_driver/amplitude?)", output)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "example_controllers", ExampleControllers)
