#!/usr/bin/python3
"""rostest accuracy_thresholds: cart_sim's residual thresholds are the accuracy guard's limits, so
/diagnostics and ~integration_error agree; conflicting or bad thresholds are refused by name."""
import subprocess
import threading
import time
import unittest

import rospy
import rostest
from birkhoff_cart.msg import IntegrationError
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from std_srvs.srv import SetBool

PACKAGE = "birkhoff_cart"


class AccuracyThresholds(unittest.TestCase):
    def test_1_diagnostics_and_integration_error_give_the_same_verdict(self):
        rospy.init_node("accuracy_thresholds", anonymous=True)
        lock = threading.Lock()
        statuses, errors = [], []

        def on_diagnostics(message):
            with lock:
                statuses.extend(s for s in message.status if "simulation" in s.name)

        def on_error(message):
            with lock:
                errors.append(message)

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=100)
        rospy.Subscriber("/cart_sim/integration_error", IntegrationError, on_error, queue_size=1000)
        rospy.wait_for_service("/cart_sim/pause", timeout=30)
        time.sleep(1.0)  # the subscriptions connect
        self.assertTrue(rospy.ServiceProxy("/cart_sim/pause", SetBool)(False).success)
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline:
            with lock:
                if (errors and errors[-1].accuracy_level == IntegrationError.ACCURACY_ERROR and statuses and
                        statuses[-1].level == DiagnosticStatus.ERROR):
                    break
            time.sleep(0.1)
        with lock:
            self.assertTrue(errors and statuses, "no messages")
            last_error, last_status = errors[-1], statuses[-1]
            self.assertEqual(last_error.accuracy_level, IntegrationError.ACCURACY_ERROR, last_error.accuracy_status)
            self.assertIn("p2_balance", last_error.accuracy_status)
            self.assertEqual(last_status.level, DiagnosticStatus.ERROR, last_status.message)
            self.assertIn("accuracy ERROR: p2_balance", last_status.message)
            # Never two verdicts: no status says more than the guard's line, and every status in
            # ERROR names what the guard names.
            for status in statuses:
                if status.level != DiagnosticStatus.OK:
                    self.assertIn("accuracy", status.message)
                self.assertNotIn("threshold", status.message)

    def run_refused(self, *parameters):
        result = subprocess.run(["rosrun", PACKAGE, "cart_sim", "__name:=refused_cart", "__ns:=/refused",
                                 "_scene:=" + rospy.get_param("/cart_sim/scene"), "_publish_clock:=false",
                                 "_bag_path:="] + list(parameters),
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                timeout=60, stdin=subprocess.DEVNULL)
        self.assertEqual(result.returncode, 2, result.stdout)
        return result.stdout

    def test_2_a_pair_beside_its_accuracy_quantity_is_refused(self):
        output = self.run_refused("_p2_residual_warn:=1e-6", "_accuracy/p2_balance:=off")
        self.assertIn("parameters /refused/refused_cart/p2_residual_warn and /refused/refused_cart/accuracy/p2_balance "
                      "both set the limits of p2_balance; keep one", output)

    def test_3_warn_above_error_is_refused(self):
        output = self.run_refused("_energy_residual_warn:=1.0")
        self.assertIn("parameters /refused/refused_cart/energy_residual_warn and "
                      "/refused/refused_cart/energy_residual_error need 0 < warn <= error", output)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "accuracy_thresholds", AccuracyThresholds)
