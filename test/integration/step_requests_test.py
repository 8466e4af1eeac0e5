#!/usr/bin/python3
"""rostest step_requests: cart_sim's ~step cannot run away (docs/ros_interface.md, "~step").
Before the fix a `~step 4294967295` stepped for hours, ~pause and ~reset answered while the steps
went on, a second call waited behind the first, refusals answered t = 0 and unpausing during a step
stopped /clock for as long as the step had run ahead."""
import threading
import time
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty, SetBool

from birkhoff_cart.srv import StepRun

STEP = 0.001            # h [s]
MAX_STEPS = 100000      # StepRequests::kMaxSteps
LONG = MAX_STEPS        # a call of several seconds at this cost per step
CANCEL_AFTER = 0.5      # wall time before the cancelling call [s]
PROMPT = 2.0            # an answer that comes within this is "at once" [s of wall time]


class StepRequestsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("step_requests_test", anonymous=True)
        cls.lock = threading.Lock()
        cls.clock = None
        rospy.Subscriber("/clock", Clock, cls.on_clock, queue_size=10)
        rospy.wait_for_service("/cart_sim/step", timeout=30.0)
        cls.step = rospy.ServiceProxy("/cart_sim/step", StepRun)
        cls.pause = rospy.ServiceProxy("/cart_sim/pause", SetBool)
        cls.reset = rospy.ServiceProxy("/cart_sim/reset", Empty)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and cls.scene_time() is None:
            time.sleep(0.05)

    @classmethod
    def on_clock(cls, message):
        with cls.lock:
            cls.clock = message.clock.to_sec()

    @classmethod
    def scene_time(cls):
        with cls.lock:
            return cls.clock

    def call_in_background(self, steps):
        """Calls ~step on a thread of its own; returns (thread, answer holder)."""
        answer = {}

        def call():
            answer["response"] = rospy.ServiceProxy("/cart_sim/step", StepRun)(steps)
            answer["at"] = time.monotonic()

        thread = threading.Thread(target=call, daemon=True)
        thread.start()
        return thread, answer

    def answered_within(self, thread, answer, seconds):
        thread.join(seconds)
        self.assertFalse(thread.is_alive(), f"~step did not answer within {seconds} s")
        return answer["response"]

    def test_1_a_refused_step_answers_the_current_scene_time(self):
        self.pause(False)
        time.sleep(0.3)
        answer = self.step(10)  # the run is not paused
        self.assertFalse(answer.success)
        self.assertIn("not paused", answer.message)
        self.assertGreater(answer.time, 0.1, answer.message)  # before: 0.0
        self.assertAlmostEqual(answer.time, self.scene_time(), delta=0.5)
        self.assertIn(f"t = ", answer.message)

    def test_2_a_step_beyond_the_maximum_is_refused_at_once(self):
        paused_at = float(self.pause(True).message.split("t = ")[1].split(" s")[0])
        thread, answer = self.call_in_background(4294967295)
        response = self.answered_within(thread, answer, PROMPT)
        self.assertFalse(response.success)
        self.assertEqual(response.steps_taken, 0)
        self.assertIn(f"more than the {MAX_STEPS}", response.message)
        self.assertAlmostEqual(response.time, paused_at, delta=1e-6)

    def cancel_a_long_step(self, cancel):
        """Starts a long ~step, calls `cancel` after CANCEL_AFTER, returns the step's answer and the
        wall time it took to come after the cancelling call."""
        self.pause(True)
        thread, answer = self.call_in_background(LONG)
        time.sleep(CANCEL_AFTER)
        cancelled_at = time.monotonic()
        cancel()
        response = self.answered_within(thread, answer, PROMPT)
        return response, answer["at"] - cancelled_at

    def test_3_pause_cancels_a_step_at_the_next_step(self):
        response, delay = self.cancel_a_long_step(lambda: self.pause(True))
        self.assertFalse(response.success, response.message)
        self.assertLess(response.steps_taken, LONG)
        self.assertIn("cancelled by ~pause", response.message)
        self.assertLess(delay, PROMPT)
        # /clock messages the node published before it answered may still be on their way (it
        # publishes one per step of a ~step run); once they are in, the clock stays at the time the
        # step was cancelled.
        time.sleep(0.5)
        settled = self.scene_time()
        self.assertAlmostEqual(settled, response.time, delta=1e-6, msg="the run went on after ~pause")
        time.sleep(0.5)
        self.assertEqual(self.scene_time(), settled, "the run went on after ~pause")

    def test_4_reset_cancels_a_step_and_the_new_run_stays_paused(self):
        response, _ = self.cancel_a_long_step(lambda: self.reset())
        self.assertFalse(response.success, response.message)
        self.assertIn("cancelled by ~reset", response.message)
        self.assertEqual(response.time, 0.0)  # the new run's start
        time.sleep(0.5)
        one = self.step(1)  # the new run did not step on: one step lands on t0 + h
        self.assertTrue(one.success, one.message)
        self.assertAlmostEqual(one.time, STEP, delta=1e-12)

    def test_5_a_second_step_is_refused_at_once_with_the_current_time(self):
        self.pause(True)
        thread, answer = self.call_in_background(LONG)
        time.sleep(CANCEL_AFTER)
        started = time.monotonic()
        second = self.step(1)
        took = time.monotonic() - started
        try:
            self.assertFalse(second.success, second.message)
            self.assertIn("another ~step call is being served", second.message)
            self.assertLess(took, PROMPT, "the second call waited for the first")
            self.assertGreater(second.time, 0.0)
        finally:
            self.pause(True)
            self.answered_within(thread, answer, PROMPT)

    def test_6_unpausing_during_a_step_resumes_the_clock_at_once(self):
        response, _ = self.cancel_a_long_step(lambda: self.pause(False))
        self.assertIn("cancelled by ~pause false", response.message)
        time.sleep(0.2)
        first = self.scene_time()
        time.sleep(1.0)
        advanced = self.scene_time() - first  # [s of scene time] in 1 s of wall time, real-time factor 1
        self.assertGreater(advanced, 0.5, "/clock stalled after ~pause false during a ~step")
        self.assertLess(advanced, 1.5, "/clock ran faster than real time")
        self.pause(True)


if __name__ == "__main__":
    rostest.rosrun("birkhoff_cart", "step_requests", StepRequestsTest)
