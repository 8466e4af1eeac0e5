#!/usr/bin/python3
"""rostest ground_truth: ground_truth beside odom (docs/odometry_sensor.md). Three carts on the same
slalom, 3 s published at 20 Hz: `exact` (odometry sensor off), `noisy` and `twin` (the
noisy_odometry scene: sensor on, seed 7)."""
import math
import os
import threading
import time
import unittest

import rosbag
import rospy
import rostest
from nav_msgs.msg import Odometry
from std_srvs.srv import Empty, SetBool
from tf2_msgs.msg import TFMessage

from birkhoff_cart.srv import SetCartState, StepRun

INSTANTS = [round(0.05 * k, 9) for k in range(1, 61)]  # the publish instants of the 3 s run [s]
CARTS = ("exact", "noisy", "twin")


def key_of(message):
    """Everything an Odometry says about the motion, for bit-for-bit comparison."""
    p, t = message.pose.pose, message.twist.twist
    return (p.position.x, p.position.y, p.orientation.z, p.orientation.w, t.linear.x, t.linear.y, t.angular.z)


def by_stamp(messages):
    return {round(m.header.stamp.to_sec(), 9): m for m in messages}


class GroundTruth(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("ground_truth_test", anonymous=True)
        cls.lock = threading.Lock()
        cls.received = {(cart, topic): [] for cart in CARTS for topic in ("odom", "ground_truth")}
        cls.static_transforms = []
        subscribers = [rospy.Subscriber(f"/{cart}/{topic}", Odometry, cls.on_message, callback_args=(cart, topic),
                                        queue_size=1000) for cart, topic in cls.received]
        rospy.Subscriber("/tf_static", TFMessage, lambda message: cls.static_transforms.extend(message.transforms))
        for cart in CARTS:
            rospy.wait_for_service(f"/{cart}/cart_sim/pause", timeout=30.0)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and any(s.get_num_connections() == 0 for s in subscribers):
            time.sleep(0.05)
        for cart in CARTS:  # all three together
            rospy.ServiceProxy(f"/{cart}/cart_sim/pause", SetBool)(False)
        cls.wait_for(lambda: all(3.0 in by_stamp(cls.received[(cart, topic)])
                                 for cart in ("exact", "noisy") for topic in ("odom", "ground_truth")))
        cls.wait_for(lambda: 3.0 in by_stamp(cls.received[("twin", "odom")]))
        rospy.ServiceProxy("/twin/cart_sim/pause", SetBool)(True)
        time.sleep(0.3)
        with cls.lock:
            cls.first_run = {key: by_stamp(messages) for key, messages in cls.received.items()}

    @classmethod
    def wait_for(cls, condition, seconds=60.0):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            with cls.lock:
                if condition():
                    return
            time.sleep(0.05)
        raise AssertionError(f"not reached within {seconds} s")

    @classmethod
    def on_message(cls, message, key):
        with cls.lock:
            cls.received[key].append(message)

    def series(self, cart, topic):
        run = self.first_run[(cart, topic)]
        for instant in INSTANTS:
            self.assertIn(instant, run, f"/{cart}/{topic} published nothing at t = {instant} s")
        return [run[instant] for instant in INSTANTS]

    def test_1_sensor_off_odom_is_the_ground_truth(self):
        for odom, truth in zip(self.series("exact", "odom"), self.series("exact", "ground_truth")):
            self.assertEqual(key_of(odom), key_of(truth), f"t = {odom.header.stamp.to_sec()} s")
            self.assertEqual((odom.header.frame_id, odom.child_frame_id), ("odom", "base_link"))
            # Its own child frame: map -> base_link would have two sources, the ground truth
            # and tf's map -> odom -> base_link, which disagree as soon as a sensor is on.
            self.assertEqual((truth.header.frame_id, truth.child_frame_id), ("map", "base_link_ground_truth"))
            self.assertEqual(max(abs(c) for c in truth.pose.covariance), 0.0)
        # The world frame: the identity map -> odom, latched on /tf_static.
        self.wait_for(lambda: any(t.child_frame_id == "noisy/odom" for t in self.static_transforms), 10.0)
        for transform in self.static_transforms:
            self.assertEqual(transform.header.frame_id, "map")
            self.assertEqual(transform.transform.rotation.w, 1.0)
            self.assertEqual(transform.transform.translation.x, 0.0)

    def test_1b_publish_world_tf_false_leaves_map_to_odom_to_the_user(self):
        rospy.wait_for_service("/local/cart_sim/pause", timeout=30.0)  # the fourth cart is up
        self.wait_for(lambda: any(t.child_frame_id == "noisy/odom" for t in self.static_transforms), 10.0)
        time.sleep(1.0)  # a latched /tf_static of the fourth cart would have arrived by now
        with self.lock:
            children = [t.child_frame_id for t in self.static_transforms]
        self.assertNotIn("local/odom", children, "~publish_world_tf false still published map -> odom")
        self.assertIn("noisy/odom", children)

    def test_2_sensor_on_ground_truth_is_the_noise_free_run_bit_for_bit(self):
        for truth, exact in zip(self.series("noisy", "ground_truth"), self.series("exact", "odom")):
            self.assertEqual(key_of(truth), key_of(exact), f"t = {truth.header.stamp.to_sec()} s")

    def test_3_sensor_on_odom_drifts_within_its_covariance_and_repeats_for_the_seed(self):
        traces = []
        for odom, twin, truth in zip(self.series("noisy", "odom"), self.series("twin", "odom"),
                                     self.series("noisy", "ground_truth")):
            self.assertEqual(key_of(odom), key_of(twin), f"same seed, other run: t = {odom.header.stamp.to_sec()} s")
            self.assertEqual((odom.header.frame_id, odom.child_frame_id), ("noisy/odom", "noisy/base_link"))
            self.assertEqual((truth.header.frame_id, truth.child_frame_id), ("map", "noisy/base_link_ground_truth"))
            covariance = odom.pose.covariance
            traces.append(covariance[0] + covariance[7])
            gap = math.hypot(odom.pose.pose.position.x - truth.pose.pose.position.x,
                             odom.pose.pose.position.y - truth.pose.pose.position.y)
            self.assertLess(gap, 6.0 * math.sqrt(traces[-1]) + 2e-3, f"t = {odom.header.stamp.to_sec()} s")
            self.assertEqual(covariance[1], covariance[6])  # symmetric
            self.assertGreater(odom.twist.covariance[0], 0.0)
        self.assertNotEqual(key_of(self.series("noisy", "odom")[-1]), key_of(self.series("noisy", "ground_truth")[-1]))
        self.assertGreater(traces[-1], traces[0])
        self.assertEqual(traces, sorted(traces), "the position variance of dead reckoning only grows")

    def test_4_reset_runs_the_noise_again_from_the_seed(self):
        with self.lock:
            for topic in ("odom", "ground_truth"):
                self.received[("twin", topic)].clear()
        rospy.ServiceProxy("/twin/cart_sim/reset", Empty)()
        answer = rospy.ServiceProxy("/twin/cart_sim/step", StepRun)(100)  # 1 s
        self.assertTrue(answer.success, answer.message)
        self.wait_for(lambda: 1.0 in by_stamp(self.received[("twin", "odom")]), 10.0)
        with self.lock:
            again = by_stamp(self.received[("twin", "odom")])
        for instant in INSTANTS[:20]:
            self.assertEqual(key_of(again[instant]), key_of(self.first_run[("twin", "odom")][instant]),
                             f"t = {instant} s")

    def test_5_a_teleport_restarts_the_odometry_at_the_new_pose(self):
        with self.lock:  # the earlier runs published at the same instants
            for topic in ("odom", "ground_truth"):
                self.received[("twin", topic)].clear()
        set_state = rospy.ServiceProxy("/twin/cart_sim/set_state", SetCartState)
        answer = set_state(x=-4.0, y=3.0, heading=1.0, steering_angle=0.0, forward_speed=1.0, steering_rate=0.0)
        self.assertTrue(answer.success, answer.message)
        stepped = rospy.ServiceProxy("/twin/cart_sim/step", StepRun)(5)
        self.assertTrue(stepped.success, stepped.message)
        instant = round(stepped.time, 9)  # a publish instant: 5 steps of 10 ms
        self.wait_for(lambda: all(instant in by_stamp(self.received[("twin", topic)]) for topic in ("odom", "ground_truth")),
                      10.0)
        with self.lock:
            odom = by_stamp(self.received[("twin", "odom")])[instant]
            truth = by_stamp(self.received[("twin", "ground_truth")])[instant]
        self.assertAlmostEqual(odom.pose.pose.position.x, -4.0, delta=0.1)
        self.assertAlmostEqual(odom.pose.pose.position.y, 3.0, delta=0.1)
        self.assertLess(math.hypot(odom.pose.pose.position.x - truth.pose.pose.position.x,
                                   odom.pose.pose.position.y - truth.pose.pose.position.y), 0.01)
        self.assertLess(odom.pose.covariance[0], 1e-4)

    def test_6_the_bag_holds_both_and_the_world_frame(self):
        bag_path = rospy.get_param("/noisy/cart_sim/bag_path")
        # The noisy cart's run ended at 3 s: the node closed its bag and exited.
        self.wait_for(lambda: os.path.isfile(bag_path) and not os.path.exists(bag_path + ".active"), 10.0)
        counts = {}
        with rosbag.Bag(bag_path) as bag:
            for topic, message, _ in bag.read_messages():
                counts[topic] = counts.get(topic, 0) + 1
                if topic == "/tf_static":
                    self.assertEqual(message.transforms[0].header.frame_id, "map")
                    self.assertEqual(message.transforms[0].child_frame_id, "noisy/odom")
        self.assertEqual(counts.get("/noisy/ground_truth"), 60)
        self.assertEqual(counts.get("/noisy/odom"), 60)
        self.assertEqual(counts.get("/tf_static"), 1)

if __name__ == "__main__":
    rostest.rosrun("birkhoff_cart", "ground_truth", GroundTruth)
