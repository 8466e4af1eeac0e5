#!/usr/bin/python3
"""rostest tf_tools: tf_echo (package tf) and tf2_tools' echo.py print the transform odom →
base_link that cart_sim broadcasts, as a user would run them beside sim.launch."""
import subprocess
import time
import unittest

import rostest

LISTEN = 20.0  # [s of wall time] at most, for the first transform a tool prints


def first_transform(command, marker):
    """Runs `command` until its output holds `marker` (then stops it); returns the output so far."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               stdin=subprocess.DEVNULL, universal_newlines=True)
    output = []
    deadline = time.monotonic() + LISTEN
    try:
        while time.monotonic() < deadline:
            line = process.stdout.readline()
            if not line:
                break  # the tool exited
            output.append(line)
            if marker in line:
                break
    finally:
        process.kill()
        process.wait()
    return "".join(output)


class TfTools(unittest.TestCase):
    def test_tf_echo_prints_the_cart_pose(self):
        output = first_transform(["rosrun", "tf", "tf_echo", "odom", "base_link"], "- Rotation:")
        self.assertIn("- Translation: [", output, output)
        self.assertIn("- Rotation:", output, output)

    def test_tf2_echo_prints_the_cart_pose(self):
        output = first_transform(["rosrun", "tf2_tools", "echo.py", "odom", "base_link"], "- Rotation:")
        self.assertIn("- Translation: [", output, output)
        self.assertIn("- Rotation:", output, output)


if __name__ == "__main__":
    rostest.rosrun("birkhoff_cart", "tf_tools", TfTools)
