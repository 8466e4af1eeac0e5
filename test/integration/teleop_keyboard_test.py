#!/usr/bin/python3
"""rostest teleop_keyboard: the keyboard teleop in a pseudo-terminal; its cmd_vel read back."""
import os
import pty
import subprocess
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist

PACKAGE = "birkhoff_cart"
WAIT = 15.0  # [s of wall time], only against hangs


class TeleopKeyboard(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("teleop_keyboard_test", anonymous=True)
        cls.lock = threading.Lock()
        cls.commands = []
        rospy.Subscriber("/teleop_test/cmd_vel", Twist, cls.on_command, queue_size=100)

    @classmethod
    def on_command(cls, message):
        with cls.lock:
            cls.commands.append((message.linear.x, message.angular.z))

    def wait_for_command(self, speed, yaw_rate):
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            with self.lock:
                if self.commands and self.commands[-1] == (speed, yaw_rate):
                    return
            time.sleep(0.05)
        with self.lock:
            last = self.commands[-1] if self.commands else None
        self.fail("no cmd_vel (%g, %g); the last was %s" % (speed, yaw_rate, last))

    def test_keys_drive_and_q_stops(self):
        leader, follower = pty.openpty()
        process = subprocess.Popen(["rosrun", PACKAGE, "teleop_keyboard", "__ns:=/teleop_test"],
                                   stdin=follower, stdout=follower, stderr=follower)
        os.close(follower)
        try:
            self.wait_for_command(0.0, 0.0)  # published at ~rate from the start
            os.write(leader, b"ww")
            self.wait_for_command(0.5, 0.0)
            os.write(leader, b"a")
            self.wait_for_command(0.5, 0.1)
            os.write(leader, b"dds")
            self.wait_for_command(0.25, -0.1)
            os.write(leader, b" ")
            self.wait_for_command(0.0, 0.0)
            os.write(leader, b"wwwwwwwwwwwwwwwwwwwww")  # 21 × 0.25 m/s, clamped at ~max_speed
            self.wait_for_command(3.0, 0.0)
            os.write(leader, b"q")
            self.assertEqual(process.wait(timeout=WAIT), 0)
            self.wait_for_command(0.0, 0.0)  # the stop before quitting
        finally:
            if process.poll() is None:
                process.kill()
            os.close(leader)

    def test_refuses_without_a_terminal(self):
        result = subprocess.run(["rosrun", PACKAGE, "teleop_keyboard", "__ns:=/teleop_test_pipe"],
                                stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                universal_newlines=True, timeout=WAIT)
        self.assertEqual(result.returncode, 2, result.stdout)
        self.assertIn("stdin is not a terminal", result.stdout)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "teleop_keyboard", TeleopKeyboard)
