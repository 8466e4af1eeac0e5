#!/usr/bin/python3
"""rostest node_events: cart_sim's ~events (docs/events.md) on the paper's special case (chi = t,
pi1 = 1 + ln tan(t/2) in closed form). For a node at fixed steps (the events as a list) and one under
the adaptive control (the events as one ';'-separated string, as sim.launch's events:= gives them):
the terminal crossing pi1 = 1.2 m is published at t = 2 atan(e^0.2) and pauses the node there; after
~pause false the crossing chi = 2.5 rad is published at t = 2.5 s; the falling event never is."""
import math
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from std_srvs.srv import SetBool

from birkhoff_cart.msg import CartEvent

PI1_CROSSING = 2.0 * math.atan(math.exp(0.2))  # [s]
CHI_CROSSING = 2.5                            # [s]
STEP = 0.01                                   # the scenes' h (the output step under the control) [s]
STAMP_TOLERANCE = 2e-9  # [s]: the crossing to 1e-10 s, its stamp rounded to the nanosecond


class NodeEvents(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("node_events_test", anonymous=True)
        cls.lock = threading.Lock()
        cls.events = {"fixed": [], "adaptive": []}
        cls.odometry = {"fixed": [], "adaptive": []}
        subscribers = []
        for cart in cls.events:
            subscribers.append(rospy.Subscriber(f"/{cart}/cart_sim/events", CartEvent,
                                                lambda m, c=cart: cls.on_message(cls.events[c], m), queue_size=100))
            subscribers.append(rospy.Subscriber(f"/{cart}/odom", Odometry,
                                                lambda m, c=cart: cls.on_message(cls.odometry[c], m), queue_size=1000))
            rospy.wait_for_service(f"/{cart}/cart_sim/pause", timeout=30.0)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and any(s.get_num_connections() == 0 for s in subscribers):
            time.sleep(0.05)

    @classmethod
    def on_message(cls, into, message):
        with cls.lock:
            into.append(message)

    def wait_for(self, into, count, seconds=20.0):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            with self.lock:
                if len(into) >= count:
                    return list(into)
            time.sleep(0.01)
        with self.lock:
            self.fail(f"{len(into)} of {count} messages after {seconds} s")

    def check_cart(self, cart):
        pause = rospy.ServiceProxy(f"/{cart}/cart_sim/pause", SetBool)
        self.assertTrue(pause(False).success)
        first = self.wait_for(self.events[cart], 1)[0]
        self.assertEqual(first.event, "pi1=1.2,terminal")
        self.assertEqual(first.occurrence, 1)
        self.assertTrue(first.terminal)
        self.assertAlmostEqual(first.header.stamp.to_sec(), PI1_CROSSING, delta=STAMP_TOLERANCE)
        self.assertAlmostEqual(first.chi, PI1_CROSSING, delta=1e-9, msg="chi = t on the paper's case")
        self.assertEqual(first.header.frame_id, "odom")
        # Paused at the end of the step the crossing fell in (h = 10 ms; an instant there is published), and
        # no step after it.
        time.sleep(0.5)
        with self.lock:
            stamps = [m.header.stamp.to_sec() for m in self.odometry[cart]]
            held = len(self.events[cart])
        self.assertTrue(stamps, "no odom before the crossing")
        self.assertLess(max(stamps), PI1_CROSSING + STEP)
        self.assertEqual(held, 1, "an event after the terminal one while paused")
        time.sleep(0.3)
        with self.lock:
            self.assertEqual(len(self.odometry[cart]), len(stamps), "the node stepped on while paused")
        self.assertTrue(pause(False).success)
        second = self.wait_for(self.events[cart], 2)[1]
        self.assertEqual(second.event, "chi=2.5")
        self.assertFalse(second.terminal)
        self.assertAlmostEqual(second.header.stamp.to_sec(), CHI_CROSSING, delta=STAMP_TOLERANCE)
        self.assertAlmostEqual(second.chi, CHI_CROSSING, delta=1e-9)
        # The run goes on to its end (t = 3 s) without the falling event.
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline:
            with self.lock:
                if self.odometry[cart] and self.odometry[cart][-1].header.stamp.to_sec() >= 3.0 - 1e-9:
                    break
            time.sleep(0.02)
        time.sleep(0.2)
        with self.lock:
            self.assertGreaterEqual(self.odometry[cart][-1].header.stamp.to_sec(), 3.0 - 1e-9)
            self.assertEqual([m.event for m in self.events[cart]], ["pi1=1.2,terminal", "chi=2.5"])

    def test_fixed_steps(self):
        self.check_cart("fixed")

    def test_adaptive_control(self):
        self.check_cart("adaptive")


if __name__ == "__main__":
    rostest.rosrun("birkhoff_cart", "node_events", NodeEvents)
