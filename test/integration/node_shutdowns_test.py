#!/usr/bin/python3
"""rostest node_shutdowns: shutdowns that never abort and always stop, tried as a user would.
- `roslaunch birkhoff_cart lockstep.launch` (nodelets in one manager) started and stopped 20 times,
  every other run ending by itself at the end of its run and the others stopped by SIGINT to
  roslaunch mid-run (Ctrl-C): every run exits 0, every process of it returns 0 (roslaunch's own
  log), nothing aborts, and cart_sim's summary reaches the console each time.
- cart_sim whose ROS_MASTER_URI names a port nobody listens on (roscpp retries the master for
  ever): the first SIGINT, and the first SIGTERM, stops it within seconds with exit 0."""
import glob
import os
import re
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import unittest

import roslib.packages
import rospy
import rostest
from sensor_msgs.msg import JointState

PACKAGE = "birkhoff_cart"
RUN_LIMIT = 60.0    # [s of wall time], only against hangs
STARTS = 20         # lockstep.launch starts and stops
STOP_LIMIT = 5.0    # [s of wall time] from the signal to the exit of a node without a master


def unused_port():
    """A TCP port of 127.0.0.1 nobody listens on (bound, then released)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def default_signals():
    """In the child: SIGINT and SIGTERM as a shell's foreground process has them."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


class NodeShutdowns(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("node_shutdowns_test", anonymous=True)

    def setUp(self):
        self.directory = tempfile.mkdtemp(prefix="node_shutdowns_")

    def tearDown(self):
        shutil.rmtree(self.directory, ignore_errors=True)

    def process_returns(self, launch_pid):
        """Each process's return value as roslaunch logged it (its log is roslaunch-<host>-<pid>.log)."""
        logs = {os.path.realpath(path) for path in  # <run id>/ and the link latest/ to it
                glob.glob(os.path.join(self.directory, "*", "roslaunch-*-%d.log" % launch_pid))}
        self.assertEqual(len(logs), 1, "roslaunch's log of pid %d" % launch_pid)
        with open(logs.pop()) as file:
            text = file.read()
        returns = re.findall(r"process\[([^\]]+)\]: .*?(?:return value|exit code) (-?\d+)", text)
        return {name: int(value) for name, value in returns}

    def test_lockstep_launch_starts_and_stops_cleanly_20_times(self):
        environment = dict(os.environ, ROS_LOG_DIR=self.directory)
        for start in range(STARTS):
            interrupted = start % 2 == 1
            process = subprocess.Popen(["roslaunch", PACKAGE, "lockstep.launch",
                                        "duration:=" + ("0" if interrupted else "1")],
                                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                       stdin=subprocess.DEVNULL, env=environment)
            try:
                if interrupted:  # Ctrl-C once the loop runs
                    rospy.wait_for_message("/joint_states", JointState, timeout=RUN_LIMIT)
                    process.send_signal(signal.SIGINT)
                output, _ = process.communicate(timeout=RUN_LIMIT)
            finally:
                if process.poll() is None:
                    process.kill()
            what = "start %d (%s)\n%s" % (start + 1, "Ctrl-C" if interrupted else "ended by itself", output[-3000:])
            self.assertEqual(process.returncode, 0, what)
            self.assertNotIn("terminate called", output, what)
            self.assertNotIn("has died", output, what)
            self.assertEqual(output.count("cart_sim summary: "), 1, what)
            self.assertIn("cart_sim summary: " + ("interrupted" if interrupted else "finished"), output, what)
            returns = self.process_returns(process.pid)
            self.assertEqual(sorted(returns), ["cart_sim-2", "loop_manager-1", "steering_pd_controller-3"], what)
            self.assertEqual(returns, {name: 0 for name in returns}, what)

    def test_first_signal_stops_cart_sim_whose_master_is_unreachable(self):
        for stop in (signal.SIGINT, signal.SIGTERM):
            log_path = os.path.join(self.directory, "no_master_%d.log" % stop)
            environment = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % unused_port())
            with open(log_path, "w") as log:
                # no _param:=value arguments: ros::init would set them on the master before the
                # node installs its handlers; the node waits for the master in its first NodeHandle
                process = subprocess.Popen([roslib.packages.find_node(PACKAGE, "cart_sim")[0]],
                                           stdout=log, stderr=subprocess.STDOUT, env=environment,
                                           preexec_fn=default_signals)
            try:
                deadline = time.monotonic() + RUN_LIMIT
                while "Failed to contact master" not in open(log_path).read() and time.monotonic() < deadline:
                    time.sleep(0.05)
                self.assertIn("Failed to contact master", open(log_path).read())
                process.send_signal(stop)
                try:
                    status = process.wait(STOP_LIMIT)
                except subprocess.TimeoutExpired:
                    status = None
            finally:
                if process.poll() is None:
                    process.kill()
                    process.wait()
            self.assertEqual(status, 0, "%s: %s" % (signal.Signals(stop).name, open(log_path).read()))
            self.assertIn("stopped by a shutdown signal while starting", open(log_path).read())


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "node_shutdowns", NodeShutdowns)
